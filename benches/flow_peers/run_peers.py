#!/usr/bin/env python3
"""Our flow presets and OpenCV's flow methods, side by side, in one run.

For every Middlebury pair (<Seq>/frame10.png, frame11.png, flow10.flo) under --data (and,
with --sintel DIR, every MPI-Sintel pair <scene>/{clean,final}/frame_NNNN.png with
<scene>/flow/frame_NNNN.flo, pixels of <scene>/invalid/frame_NNNN.png excluded), runs
each of our presets (through `frf flow-bench`, which times only the estimation) and
OpenCV's Farneback, DIS (medium preset), DeepFlow and DualTVL1 (timed around `calc`
only), interleaved sequence by sequence and in a rotating order, so that the load of a
shared machine falls on all methods alike. Each timing is the median of --repeat runs.
Errors skip unknown ground truth (|u| or |v| > 1e9), as the Middlebury benchmark does.

Writes a Markdown table (EPE, AAE and seconds per method per sequence, and the means) to
--out-md and the raw numbers to --out-json.

Setup (once; the venv is git-ignored and never needed by the tests):
    python3 -m venv benches/flow_peers/.venv
    benches/flow_peers/.venv/bin/pip install opencv-contrib-python-headless numpy
    cargo build --release
Run from the repository root:
    benches/flow_peers/.venv/bin/python benches/flow_peers/run_peers.py --threads 1
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

UNKNOWN_THRESHOLD = 1e9


def read_flo(path):
    with open(path, "rb") as f:
        magic = np.fromfile(f, np.float32, 1)[0]
        if magic != np.float32(202021.25):
            raise ValueError(f"{path}: not a .flo file")
        w, h = np.fromfile(f, np.int32, 2)
        data = np.fromfile(f, np.float32, int(w) * int(h) * 2)
    return data.reshape(int(h), int(w), 2)


def errors(flow, truth, valid=None):
    known = (np.abs(truth[..., 0]) <= UNKNOWN_THRESHOLD) & (np.abs(truth[..., 1]) <= UNKNOWN_THRESHOLD)
    if valid is not None:
        known &= valid
    f = flow[known].astype(np.float64)
    t = truth[known].astype(np.float64)
    epe = np.sqrt(((f - t) ** 2).sum(-1))
    num = f[:, 0] * t[:, 0] + f[:, 1] * t[:, 1] + 1.0
    den = np.sqrt(((f**2).sum(-1) + 1.0) * ((t**2).sum(-1) + 1.0))
    aae = np.degrees(np.arccos(np.clip(num / den, -1.0, 1.0)))
    return float(epe.mean()), float(aae.mean())


def opencv_methods():
    # Parameters: OpenCV's defaults, except Farneback, which has none in the Python
    # binding (these are the values of OpenCV's own optical-flow sample).
    return {
        "opencv_farneback": lambda a, b: cv2.calcOpticalFlowFarneback(a, b, None, 0.5, 3, 15, 3, 5, 1.2, 0),
        "opencv_dis_medium": lambda a, b: cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM).calc(a, b, None),
        "opencv_deepflow": lambda a, b: cv2.optflow.createOptFlow_DeepFlow().calc(a, b, None),
        "opencv_dualtvl1": lambda a, b: cv2.optflow.DualTVL1OpticalFlow_create().calc(a, b, None),
    }


class Pair:
    """One image pair with ground truth; `group` is the directory `frf flow-bench` runs on."""

    def __init__(self, name, group, a, b, truth, invalid=None):
        self.name, self.group, self.a, self.b, self.truth, self.invalid = name, group, a, b, truth, invalid


def middlebury_pairs(root):
    return [Pair(d.name, d, d / "frame10.png", d / "frame11.png", d / "flow10.flo")
            for d in sorted(root.iterdir()) if (d / "flow10.flo").is_file()]


def sintel_pairs(root):
    pairs = []
    scenes = [root] if (root / "flow").is_dir() else sorted(d for d in root.iterdir() if (d / "flow").is_dir())
    for scene in scenes:
        for flo in sorted((scene / "flow").glob("frame_*.flo")):
            n = int(flo.stem.split("_")[1])
            for pass_ in ("clean", "final"):
                a, b = scene / pass_ / f"frame_{n:04d}.png", scene / pass_ / f"frame_{n + 1:04d}.png"
                if a.is_file() and b.is_file():
                    inv = scene / "invalid" / f"frame_{n:04d}.png"
                    pairs.append(Pair(f"{scene.name}/{pass_}/{n:04d}", scene, a, b, flo, inv if inv.is_file() else None))
    return pairs


def run_opencv(fn, pair, repeat):
    a = cv2.cvtColor(cv2.imread(str(pair.a)), cv2.COLOR_BGR2GRAY)
    b = cv2.cvtColor(cv2.imread(str(pair.b)), cv2.COLOR_BGR2GRAY)
    times, flow = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        flow = fn(a, b)
        times.append(time.perf_counter() - start)
    valid = None
    if pair.invalid is not None:
        valid = cv2.imread(str(pair.invalid), cv2.IMREAD_GRAYSCALE) <= 127
    epe, aae = errors(flow, read_flo(pair.truth), valid)
    return {"epe": epe, "aae": aae, "seconds": statistics.median(times)}


def run_frf(frf, args, group, repeat, env):
    # One sequence directory at a time (a directory holding only a link to it), so that
    # our presets interleave with the OpenCV methods. Returns results by pair name.
    with tempfile.TemporaryDirectory() as tmp:
        link = Path(tmp) / group.name
        link.symlink_to(group.resolve())
        cmd = [str(frf), "flow-bench", str(link), "--json", "--repeat", str(repeat)] + args
        out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
    found = {}
    for seq in json.loads(out)["sequences"]:
        # Middlebury sequence names are the directory's; Sintel ones start with it.
        found[seq["name"]] = {"epe": seq["epe"], "aae": seq["aae"], "seconds": seq["seconds"]}
    return found


def main():
    root = Path(__file__).resolve().parents[2]
    data_default = Path(os.environ.get("FRF_DATA_DIR", root.parent / "shared" / "data")) / "middlebury_flow"
    if not data_default.is_dir():
        data_default = Path("/work/shared/data/middlebury_flow")
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", type=Path, default=data_default, help="Middlebury directory")
    p.add_argument("--sintel", type=Path, default=None, help="also the MPI-Sintel pairs under this directory")
    p.add_argument("--frf", type=Path, default=root / "target" / "release" / "frf")
    p.add_argument("--presets", default="fast,balanced,accurate")
    p.add_argument("--extra", action="append", default=[],
                   help="extra frf configuration LABEL=ARGS, e.g. 'acc-l30=--preset accurate --set lambda=30'")
    p.add_argument("--no-opencv", action="store_true", help="only our configurations")
    p.add_argument("--only", default="", help="comma-separated OpenCV methods to keep")
    p.add_argument("--threads", type=int, default=1, help="threads for every method")
    p.add_argument("--repeat", type=int, default=3, help="timings per pair (median kept)")
    p.add_argument("--out-md", type=Path, default=None)
    p.add_argument("--out-json", type=Path, default=None)
    opts = p.parse_args()

    cv2.setNumThreads(opts.threads)
    env = dict(os.environ, RAYON_NUM_THREADS=str(opts.threads))
    seqs = middlebury_pairs(opts.data)
    if opts.sintel:
        seqs += sintel_pairs(opts.sintel)
    if not seqs:
        sys.exit(f"no Middlebury sequence under {opts.data}")

    methods = {}
    for preset in [s for s in opts.presets.split(",") if s]:
        methods[f"frf_{preset}"] = ("frf", ["--preset", preset])
    for extra in opts.extra:
        label, _, args = extra.partition("=")
        methods[label] = ("frf", args.split())
    if not opts.no_opencv:
        keep = set(opts.only.split(",")) if opts.only else None
        for name, fn in opencv_methods().items():
            if keep is None or name in keep:
                methods[name] = ("opencv", fn)

    results = {m: {} for m in methods}
    names = list(methods)
    groups = []
    for pair in seqs:
        if not groups or groups[-1][0] != pair.group:
            groups.append((pair.group, []))
        groups[-1][1].append(pair)
    for i, (group, pairs) in enumerate(groups):
        order = names[i % len(names):] + names[: i % len(names)]
        for m in order:
            kind, what = methods[m]
            if kind == "frf":
                found = run_frf(opts.frf, what, group, opts.repeat, env)
                for pair in pairs:
                    key = pair.name if pair.name in found else group.name
                    results[m][pair.name] = found[key]
            else:
                for pair in pairs:
                    results[m][pair.name] = run_opencv(what, pair, opts.repeat)
            for pair in pairs:
                r = results[m][pair.name]
                print(f"{pair.name:22s} {m:22s} EPE {r['epe']:.3f} px  AAE {r['aae']:.2f} deg  {r['seconds']:.3f} s",
                      file=sys.stderr, flush=True)

    # Means over the Middlebury pairs only (the targets' reference); Sintel is listed apart.
    midd = [s for s in seqs if "/" not in s.name]
    summary = {}
    for m in names:
        rs = [results[m][s.name] for s in midd]
        summary[m] = {k: statistics.fmean(r[k] for r in rs) for k in ("epe", "aae", "seconds")}

    meta = {
        "data": str(opts.data),
        "sequences": [s.name for s in seqs],
        "sintel": str(opts.sintel) if opts.sintel else None,
        "threads": opts.threads,
        "repeat": opts.repeat,
        "opencv": cv2.__version__,
        "cpu": platform.processor() or platform.machine(),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "command": " ".join([Path(sys.argv[0]).as_posix()] + sys.argv[1:]),
    }
    lines = [
        f"Threads per method: {opts.threads}; seconds = wall time of one pair's estimation "
        f"(median of {opts.repeat}); OpenCV {cv2.__version__} on 8-bit gray frames, ours on RGB. "
        "Cells: EPE (px) / seconds; means over the Middlebury pairs.",
        "",
        "| method | " + " | ".join(s.name for s in midd) + " | mean EPE (px) | mean AAE (deg) | mean seconds |",
        "|---|" + "---|" * len(midd) + "---|---|---|",
    ]
    for m in names:
        cells = [f"{results[m][s.name]['epe']:.3f} / {results[m][s.name]['seconds']:.3f} s" for s in midd]
        sm = summary[m]
        lines.append(f"| {m} | " + " | ".join(cells) + f" | {sm['epe']:.3f} | {sm['aae']:.2f} | {sm['seconds']:.3f} |")
    lines += ["", "AAE (deg) per sequence:", "",
              "| method | " + " | ".join(s.name for s in seqs) + " |",
              "|---|" + "---|" * len(seqs)]
    for m in names:
        lines.append(f"| {m} | " + " | ".join(f"{results[m][s.name]['aae']:.2f}" for s in seqs) + " |")
    other = [s for s in seqs if "/" in s.name]
    if other:
        lines += ["", "MPI-Sintel (invalid pixels excluded), EPE (px) / seconds:", "",
                  "| method | " + " | ".join(s.name for s in other) + " |",
                  "|---|" + "---|" * len(other)]
        for m in names:
            lines.append(f"| {m} | " + " | ".join(
                f"{results[m][s.name]['epe']:.3f} / {results[m][s.name]['seconds']:.3f} s" for s in other) + " |")
    table = "\n".join(lines)
    print(table)
    if opts.out_md:
        opts.out_md.write_text(table + "\n")
    if opts.out_json:
        opts.out_json.write_text(json.dumps({"meta": meta, "results": results, "summary": summary}, indent=2) + "\n")


if __name__ == "__main__":
    main()
