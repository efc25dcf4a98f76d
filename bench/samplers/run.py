#!/usr/bin/env python3
"""Error of each sampler against a high-spp reference, at equal spp and at equal time.

  python3 bench/samplers/run.py [--candela build/bin/candela] [--spp 64] [--ref-spp 8192]
                                [--res 64] [--threads 1] [--scenes cornell,veach-mis]

For each scene: a reference rendered once by candela's independent sampler (seed 1000, --ref-spp,
cached in --cache), then per sampler (seed 1):
  equal spp : --spp samples (sample_count = --spp, so the stratified sets are complete);
  equal time: a --time-limit of the independent sampler's measured time for --spp, passes of one
              sample (sample_count still --spp: the stratified samplers' later sets are partial).
RMSE = sqrt(mean over pixels and channels of (x - ref)^2); 'gain' = RMSE(independent) / RMSE.
The reference's own noise adds RMSE(independent) * sqrt(spp / ref_spp) in quadrature (printed as
'ref floor'). Prints a Markdown table (docs/samplers.md has one). Needs numpy only.
"""
import argparse, os, re, subprocess, sys, time
import numpy as np

SAMPLERS = ["independent", "stratified", "multijitter", "ldsampler", "sobol", "zsobol"]
SCENES = {"cornell": [], "veach-mis": ["scenes/veach-mis/scene.xml"], "caustics": ["scenes/caustics/scene.xml"]}


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    c = 3 if kind == b"PF" else 1
    return data.reshape(h, w, c).astype(np.float64)


def render(args, scene, out, sampler, seed, spp=None, time_limit=None, sample_count=None):
    cmd = [args.candela, *SCENES[scene], "--width", str(args.res), "--height", str(args.res), "--threads",
           str(args.threads), "--sampler", sampler, "--seed", str(seed), "--out", out]
    if time_limit is None:
        cmd += ["--sample-count", str(spp), "--spp-per-frame", str(spp), "--frames", "1"]
    else:  # passes of 1 spp up to the time limit
        cmd += ["--sample-count", str(sample_count), "--spp-per-frame", "1", "--frames", str(1 << 20),
                "--time-limit", f"{time_limit:.3f}"]
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    m = re.search(r"(\d+) spp", r.stderr + r.stdout)
    return dt, (int(m.group(1)) if m else spp)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--candela", default="build/bin/candela")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=8192)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--scenes", default="cornell,veach-mis")
    ap.add_argument("--samplers", default=",".join(SAMPLERS))
    ap.add_argument("--cache", default="/tmp/candela-sampler-bench")
    args = ap.parse_args()
    os.makedirs(args.cache, exist_ok=True)
    samplers = args.samplers.split(",")
    print(f"{args.res}x{args.res}, {args.spp} spp, {args.threads} thread(s), reference {args.ref_spp} spp independent\n")
    print("| scene | sampler | RMSE equal spp | gain | time (s) | RMSE equal time | spp reached | gain |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in args.scenes.split(","):
        ref_path = f"{args.cache}/{scene}_{args.res}_ref{args.ref_spp}.pfm"
        if not os.path.exists(ref_path):
            render(args, scene, ref_path, "independent", 1000, spp=args.ref_spp)
        ref = read_pfm(ref_path)
        base = {}
        t_ind = None
        for s in samplers:
            out = f"{args.cache}/{scene}_{s}.pfm"
            dt, _ = render(args, scene, out, s, 1, spp=args.spp)
            e_spp = float(np.sqrt(np.mean((read_pfm(out) - ref) ** 2)))
            if t_ind is None:
                t_ind = dt  # the first sampler (independent) sets the time budget
            dt2, reached = render(args, scene, out, s, 1, time_limit=t_ind, sample_count=args.spp)
            e_time = float(np.sqrt(np.mean((read_pfm(out) - ref) ** 2)))
            base.setdefault("spp", e_spp)
            base.setdefault("time", e_time)
            print(f"| {scene} | {s} | {e_spp:.5f} | {base['spp'] / e_spp:.2f}x | {dt:.2f} | {e_time:.5f} | {reached} | "
                  f"{base['time'] / e_time:.2f}x |", flush=True)
        print(f"| {scene} | (ref floor) | {base['spp'] * np.sqrt(args.spp / args.ref_spp):.5f} | | | | | |")


if __name__ == "__main__":
    main()
