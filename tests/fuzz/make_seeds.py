#!/usr/bin/env python3
"""Seed corpora for the fuzz harnesses, made at run time from the repository's
own data (tests/data/sample_jumps.csv, firmware_cfg/*.cfg) so nothing large is
committed: short CSV files of each layout, the same frames as an AlphaPose
result list and as OpenPose folders, and the profiles.
Usage: make_seeds.py OUT_DIR  (writes OUT_DIR/<harness>/seed_*)."""
import glob
import json
import os
import sys

TOP = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# COCO-17 index -> BODY_25 index (inverse of src/io/gs_kp_openpose.c's map)
BODY25 = [0, 16, 15, 18, 17, 5, 2, 6, 3, 7, 4, 12, 9, 13, 10, 14, 11]


def put(out, harness, name, data, prefix=b""):
    d = os.path.join(out, harness)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(prefix + data)


def rows(n_skip, n):
    with open(os.path.join(TOP, "tests", "data", "sample_jumps.csv")) as f:
        lines = f.read().splitlines()
    return lines[0], lines[1 + n_skip:1 + n_skip + n]


def kps(row):
    f = row.split(",")
    t = float(f[0])
    pts = []
    for k in range(17):
        x, y, c = f[1 + 3 * k: 4 + 3 * k]
        pts.append((float(x) if x else 0.0, float(y) if y else 0.0, float(c)))
    return t, pts


def main():
    out = sys.argv[1]
    header, body = rows(0, 12)
    _, jump = rows(40, 75)  # standing, then the first flight (take-off 2.70 s, landing 3.33 s)
    # CSV (first byte: reader options; 0 = no --layout, no --fps)
    put(out, "csv", "seed_coco17", "\n".join([header] + body) + "\n", b"\x00")
    put(out, "csv", "seed_coco17_jump", "\n".join([header] + jump) + "\n", b"\x00")
    put(out, "csv", "seed_coco17_crlf", "\r\n".join([header] + body[:3]), b"\x00")
    frame_hdr = "frame" + header[1:]
    frames = ["%d%s" % (i, r[r.index(","):]) for i, r in enumerate(body)]
    put(out, "csv", "seed_frame_fps30", "\n".join([frame_hdr] + frames) + "\n", bytes([1 << 3]))
    point = ["t,x,y,c,size"]
    for r in jump:
        t, p = kps(r)
        point.append("%.6f,%.2f,%.2f,0.9,%.1f" % (t, p[11][0], p[11][1], 40.0))
    point.append("%.6f,,,0,," % (float(jump[-1].split(",")[0]) + 0.1))
    put(out, "csv", "seed_point", "\n".join(point) + "\n", b"\x00")
    bp_hdr = "t," + ",".join("x%d,y%d,c%d" % (k, k, k) for k in range(33))
    bp = [bp_hdr]
    for r in body[:4]:
        t, p = kps(r)
        vals = [p[k % 17] for k in range(33)]
        bp.append("%.6f," % t + ",".join("%.2f,%.2f,%.3f" % v for v in vals))
    put(out, "csv", "seed_blazepose", "\n".join(bp) + "\n", b"\x00")

    # AlphaPose (first byte: fps 30, no --track) and OpenPose folders
    ap = []
    for r in jump:
        t, p = kps(r)
        idx = round(t * 30.0)
        ap.append({"image_id": "%06d.jpg" % idx, "category_id": 1,
                   "keypoints": [v for q in p for v in q], "score": 2.5, "idx": 0})
    put(out, "alphapose", "seed_jump", json.dumps(ap), b"\x00")
    two = ap[:3] + [dict(ap[1], idx=[1, 0.5], image_id=int(round(kps(jump[1])[0] * 30)))]
    put(out, "alphapose", "seed_two_people", json.dumps(two, indent=1), b"\x04")
    op_files = []
    for i, r in enumerate(body[:5]):
        _, p = kps(r)
        b25 = [0.0] * 75
        for k, j in enumerate(BODY25):
            b25[3 * j: 3 * j + 3] = p[k]
        op_files.append(json.dumps({"version": 1.3, "people": [
            {"person_id": [-1], "pose_keypoints_2d": b25, "face_keypoints_2d": []}]}))
    put(out, "openpose", "seed_body25", b"\x00".join(x.encode() for x in op_files), b"\x00")
    coco18 = [0.0] * 54
    put(out, "openpose", "seed_named", "#cam_000000000012\n" + json.dumps(
        {"people": [{"pose_keypoints_2d": coco18}]}) + "\x00#notes\n{\"people\":[]}", b"\x00")

    # the JSON tokenizer sees what the readers read
    put(out, "json_tok", "seed_alphapose", json.dumps(ap[:4]))
    put(out, "json_tok", "seed_openpose", op_files[0])

    # profiles for the config parsers
    for p in sorted(glob.glob(os.path.join(TOP, "firmware_cfg", "*.cfg"))):
        with open(p, "rb") as f:
            text = f.read()
        put(out, "config", os.path.basename(p), text)
        put(out, "sink_config", os.path.basename(p), text)


if __name__ == "__main__":
    main()
