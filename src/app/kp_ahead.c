/* kp_ahead.c - the keypoint reader in its own thread, handing over batches of
 * frames through a few slots (one lock round trip per batch, not per frame). */
#include "kp_ahead.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>

#define AHEAD_SLOTS 8
#define AHEAD_REFILL 4 /* a reader that found every slot full waits until this many are free: one wake per 4 batches */
#define AHEAD_BATCH_FRAMES 256 /* ~100 kB a slot: a few ms of reading, well inside the caches' reach */
#define AHEAD_FIRST_FRAMES 16  /* the first batch, short: the core waits for it */

typedef struct {
    gs_kpframe f[AHEAD_BATCH_FRAMES];
    kp_ahead_com com[AHEAD_BATCH_FRAMES];
    uint32_t n;
    gs_kpr_status end;   /* GS_KPR_FRAME while more frames follow this batch */
    gs_kpread_error err; /* the reader's error when end < 0 */
    uint64_t done_bytes, total_bytes;
} ahead_slot;

struct kp_ahead {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t filled_cv, freed_cv;
    unsigned filled; /* slots written and not yet given back */
    bool stop;       /* the caller gave up: the reader ends after its batch */
    gs_kpread *r;
    const gs_pipeline *com_of; /* NULL: no COM */
    ahead_slot *slot;
    /* the caller's side */
    unsigned cur;    /* slot being handed out */
    uint32_t next;   /* its next frame */
    bool have_cur;
};

static void *reader_main(void *arg)
{
    kp_ahead *q = arg;
    uint32_t batch = AHEAD_FIRST_FRAMES;
    for (unsigned w = 0;; w = (w + 1) % AHEAD_SLOTS) {
        pthread_mutex_lock(&q->mu);
        if (q->filled == AHEAD_SLOTS)
            while (q->filled > AHEAD_SLOTS - AHEAD_REFILL && !q->stop)
                pthread_cond_wait(&q->freed_cv, &q->mu);
        bool stop = q->stop;
        pthread_mutex_unlock(&q->mu);
        if (stop)
            return NULL;
        ahead_slot *s = &q->slot[w];
        s->n = 0;
        s->end = GS_KPR_FRAME;
        while (s->n < batch) {
            gs_kpr_status ks = gs_kpread_next(q->r, &s->f[s->n], &s->err);
            if (ks != GS_KPR_FRAME) {
                s->end = ks;
                break;
            }
            if (q->com_of)
                s->com[s->n].st = gs_pipeline_com(q->com_of, s->f[s->n].kp, &s->com[s->n].out);
            s->n++;
        }
        batch = AHEAD_BATCH_FRAMES;
        gs_kpread_progress(q->r, &s->done_bytes, &s->total_bytes);
        pthread_mutex_lock(&q->mu);
        q->filled++;
        pthread_cond_signal(&q->filled_cv);
        pthread_mutex_unlock(&q->mu);
        if (s->end != GS_KPR_FRAME)
            return NULL;
    }
}

kp_ahead *kp_ahead_start(gs_kpread *r, const gs_pipeline *com_of)
{
    kp_ahead *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    q->slot = malloc(AHEAD_SLOTS * sizeof *q->slot);
    q->r = r;
    q->com_of = com_of;
    bool mu = false, c1 = false, c2 = false;
    if (q->slot && (mu = pthread_mutex_init(&q->mu, NULL) == 0) &&
        (c1 = pthread_cond_init(&q->filled_cv, NULL) == 0) &&
        (c2 = pthread_cond_init(&q->freed_cv, NULL) == 0) &&
        pthread_create(&q->thread, NULL, reader_main, q) == 0)
        return q;
    if (c2)
        pthread_cond_destroy(&q->freed_cv);
    if (c1)
        pthread_cond_destroy(&q->filled_cv);
    if (mu)
        pthread_mutex_destroy(&q->mu);
    free(q->slot);
    free(q);
    return NULL;
}

gs_kpr_status kp_ahead_next(kp_ahead *q, const gs_kpframe **f, const kp_ahead_com **com,
                            gs_kpread_error *err)
{
    for (;;) {
        if (q->have_cur) {
            ahead_slot *s = &q->slot[q->cur];
            if (q->next < s->n) {
                *com = q->com_of ? &s->com[q->next] : NULL;
                *f = &s->f[q->next++];
                return GS_KPR_FRAME;
            }
            if (s->end != GS_KPR_FRAME) { /* the reader's last batch: its end, as often as asked */
                if (s->end < 0)
                    *err = s->err;
                return s->end;
            }
            pthread_mutex_lock(&q->mu);
            if (--q->filled == AHEAD_SLOTS - AHEAD_REFILL)
                pthread_cond_signal(&q->freed_cv);
            pthread_mutex_unlock(&q->mu);
            q->cur = (q->cur + 1) % AHEAD_SLOTS;
            q->have_cur = false;
        }
        pthread_mutex_lock(&q->mu);
        while (q->filled == 0)
            pthread_cond_wait(&q->filled_cv, &q->mu);
        pthread_mutex_unlock(&q->mu);
        q->have_cur = true;
        q->next = 0;
    }
}

void kp_ahead_progress(const kp_ahead *q, uint64_t *done_bytes, uint64_t *total_bytes)
{
    const ahead_slot *s = q->have_cur ? &q->slot[q->cur] : NULL;
    *done_bytes = s ? s->done_bytes : 0;
    *total_bytes = s ? s->total_bytes : 0;
}

void kp_ahead_stop(kp_ahead *q)
{
    if (!q)
        return;
    pthread_mutex_lock(&q->mu);
    q->stop = true;
    pthread_cond_signal(&q->freed_cv);
    pthread_mutex_unlock(&q->mu);
    pthread_join(q->thread, NULL);
    pthread_cond_destroy(&q->freed_cv);
    pthread_cond_destroy(&q->filled_cv);
    pthread_mutex_destroy(&q->mu);
    free(q->slot);
    free(q);
}
