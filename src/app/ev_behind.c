/* ev_behind.c - events formatted and written in their own thread: the caller
 * copies each into a ring; the thread takes what is there in one lock round
 * trip and runs the callback on it outside the lock. */
#include "ev_behind.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <time.h>

#define BEHIND_EVENTS 64 /* a second's worth of a busy trace; the caller waits beyond */
#define WAKE_EVENTS 32   /* the writer is woken by a half-full ring, not by every event */
#define POLL_NS 20000000L /* else it looks every 20 ms: no event waits longer */

struct ev_behind {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t put_cv, taken_cv;
    gs_event ring[BEHIND_EVENTS];
    unsigned head, count; /* the oldest event not yet taken, and how many are there */
    bool stop;            /* no more events: the thread ends once the ring is empty */
    gs_event_fn fn;
    void *ctx;
};

static void *writer_main(void *arg)
{
    ev_behind *q = arg;
    gs_event batch[BEHIND_EVENTS];
    for (;;) {
        pthread_mutex_lock(&q->mu);
        while (q->count == 0 && !q->stop) {
            struct timespec until;
            clock_gettime(CLOCK_MONOTONIC, &until);
            until.tv_nsec += POLL_NS;
            if (until.tv_nsec >= 1000000000L) {
                until.tv_sec++;
                until.tv_nsec -= 1000000000L;
            }
            pthread_cond_timedwait(&q->put_cv, &q->mu, &until);
        }
        unsigned n = q->count;
        for (unsigned i = 0; i < n; i++)
            batch[i] = q->ring[(q->head + i) % BEHIND_EVENTS];
        q->head = (q->head + n) % BEHIND_EVENTS;
        q->count = 0;
        bool stop = q->stop;
        pthread_cond_signal(&q->taken_cv);
        pthread_mutex_unlock(&q->mu);
        for (unsigned i = 0; i < n; i++)
            q->fn(q->ctx, &batch[i]);
        if (n == 0 && stop)
            return NULL;
    }
}

/* put_cv's timed waits on the monotonic clock: a clock step cannot stall them */
static int monotonic_cond_init(pthread_cond_t *cv)
{
    pthread_condattr_t a;
    if (pthread_condattr_init(&a) != 0)
        return -1;
    int rc = pthread_condattr_setclock(&a, CLOCK_MONOTONIC);
    if (rc == 0)
        rc = pthread_cond_init(cv, &a);
    pthread_condattr_destroy(&a);
    return rc;
}

ev_behind *ev_behind_start(gs_event_fn fn, void *ctx)
{
    ev_behind *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    q->fn = fn;
    q->ctx = ctx;
    bool mu = false, c1 = false, c2 = false;
    if ((mu = pthread_mutex_init(&q->mu, NULL) == 0) &&
        (c1 = monotonic_cond_init(&q->put_cv) == 0) &&
        (c2 = pthread_cond_init(&q->taken_cv, NULL) == 0) &&
        pthread_create(&q->thread, NULL, writer_main, q) == 0)
        return q;
    if (c2)
        pthread_cond_destroy(&q->taken_cv);
    if (c1)
        pthread_cond_destroy(&q->put_cv);
    if (mu)
        pthread_mutex_destroy(&q->mu);
    free(q);
    return NULL;
}

void ev_behind_put(ev_behind *q, const gs_event *ev)
{
    pthread_mutex_lock(&q->mu);
    while (q->count == BEHIND_EVENTS)
        pthread_cond_wait(&q->taken_cv, &q->mu);
    q->ring[(q->head + q->count) % BEHIND_EVENTS] = *ev;
    if (++q->count == WAKE_EVENTS)
        pthread_cond_signal(&q->put_cv);
    pthread_mutex_unlock(&q->mu);
}

void ev_behind_stop(ev_behind *q)
{
    if (!q)
        return;
    pthread_mutex_lock(&q->mu);
    q->stop = true;
    pthread_cond_signal(&q->put_cv);
    pthread_mutex_unlock(&q->mu);
    pthread_join(q->thread, NULL);
    pthread_cond_destroy(&q->taken_cv);
    pthread_cond_destroy(&q->put_cv);
    pthread_mutex_destroy(&q->mu);
    free(q);
}
