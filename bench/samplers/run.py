#!/usr/bin/env python3
"""Error of each sampler against a high-spp reference, at equal spp and at equal time.

  $PY bench/samplers/run.py [--candela build/bin/candela] [--spp 64] [--ref-spp 8192] [--res 64]
                            [--threads 2] [--seeds 3] [--scenes cornell,veach-mis]

For each scene: a reference rendered once by candela's independent sampler (seed 1000, --ref-spp,
cached in --cache), then per sampler and seed (seeds 1..--seeds):
  equal spp : --spp samples in one pass, sample_count = --spp (complete stratified sets); the
              render's wall time (the fastest over the seeds) is the sampler's cost;
  equal time: the spp the sampler renders in the independent sampler's time,
              min(spp, floor(spp * cost_independent / cost_sampler)), with sample_count still --spp: a
              render stopped early, as --time-limit would stop it (a slower stratified sampler
              ends inside its last set, which stays unbiased).
RMSE = sqrt(mean over seeds, pixels and channels of (x - ref)^2 - MSE_ref): the reference's own
expected MSE, MSE_ref = MSE_independent(spp) * spp / ref_spp (it is that sampler at ref_spp), is
taken out so that RMSE estimates the error against the true image; 'gain' = RMSE(independent) /
RMSE. 'cost' is the sampler's cost per sample relative to the independent sampler's: by default
instructions per sample counted by callgrind (32 x 32, 1 thread, Ir(12 spp) - Ir(4 spp), so that
start-up cancels), deterministic where wall times on a shared machine vary by +-30%; --cost wall
uses candela's own render time (its summary line, the fastest over the seeds) instead. Prints a Markdown table (docs/samplers.md has one). Needs numpy only.
"""
import argparse, os, re, subprocess, sys
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchlib import SCENES, read_pfm, run_candela  # noqa: E402

SAMPLERS = ["independent", "stratified", "multijitter", "ldsampler", "orthogonal", "sobol", "zsobol"]



def render(args, scene, out, sampler, seed, spp, sample_count):
    cmd = [args.candela, *SCENES[scene], "--width", str(args.res), "--height", str(args.res), "--threads",
           str(args.threads), "--sampler", sampler, "--seed", str(seed), "--out", out,
           "--sample-count", str(sample_count), "--spp-per-frame", str(spp), "--frames", "1"]
    return run_candela(cmd)[1]


def instructions(args, scene, sampler, spp):
    """Instructions (callgrind Ir) of a 32 x 32, 1-thread render of spp samples (start-up included)."""
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", args.candela, *SCENES[scene], "--width",
           "32", "--height", "32", "--threads", "1", "--sampler", sampler, "--sample-count", str(args.spp),
           "--spp-per-frame", str(spp), "--frames", "1", "--quiet", "--out", f"{args.cache}/ir.pfm"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    m = re.search(r"refs:\s+([0-9,]+)", r.stderr)
    if r.returncode != 0 or not m:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return int(m.group(1).replace(",", ""))


def cost(args, scene, sampler):
    """Instructions per sample: the difference of two renders (12 and 4 spp) removes start-up."""
    return (instructions(args, scene, sampler, 12) - instructions(args, scene, sampler, 4)) / (8 * 32 * 32)


def measure(args, scene, sampler, spp, ref, ref_mse):
    """RMSE over the seeds with the reference's own expected MSE (ref_mse) taken out, and the time."""
    mse, times = [], []
    for seed in range(1, args.seeds + 1):
        out = f"{args.cache}/{scene}_{sampler}_{seed}.pfm"
        times.append(render(args, scene, out, sampler, seed, spp, args.spp))
        mse.append(np.mean((read_pfm(out) - ref) ** 2))
    return float(np.sqrt(max(np.mean(mse) - ref_mse, 0.0))), min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--candela", default="build/bin/candela")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=8192)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--cost", choices=["callgrind", "wall"], default="callgrind",
                    help="what 'equal time' equalises: instructions per sample (deterministic) or wall time")
    ap.add_argument("--scenes", default="cornell,veach-mis")
    ap.add_argument("--samplers", default=",".join(SAMPLERS))
    ap.add_argument("--cache", default="/tmp/candela-sampler-bench")
    args = ap.parse_args()
    os.makedirs(args.cache, exist_ok=True)
    samplers = args.samplers.split(",")
    print(f"{args.res}x{args.res}, {args.spp} spp, {args.threads} thread(s), {args.seeds} seeds, "
          f"reference {args.ref_spp} spp independent\n")
    print("| scene | sampler | RMSE at equal spp | gain | wall time (s) | cost | spp at equal time | RMSE at equal time | gain |")
    print("|---|---|---|---|---|---|---|---|---|")
    for scene in args.scenes.split(","):
        ref_path = f"{args.cache}/{scene}_{args.res}_ref{args.ref_spp}.pfm"
        if not os.path.exists(ref_path):
            render(args, scene, ref_path, "independent", 1000, args.ref_spp, args.ref_spp)
        ref = read_pfm(ref_path)
        base_spp = base_time = t_ind = None
        # The reference is the independent sampler at ref_spp: its expected MSE is the independent
        # sampler's at spp times spp / ref_spp (measured below, with the reference's noise in it).
        raw, _ = measure(args, scene, "independent", args.spp, ref, 0.0)
        ref_mse = raw ** 2 * args.spp / (args.ref_spp + args.spp)
        for s in samplers:
            e_spp, t = measure(args, scene, s, args.spp, ref, ref_mse)
            c = cost(args, scene, s) if args.cost == "callgrind" else t
            if t_ind is None:
                t_ind = c  # the first sampler (independent) sets the time budget
            n = min(args.spp, int(args.spp * t_ind / c)) if s != samplers[0] else args.spp
            e_time = e_spp if n == args.spp else measure(args, scene, s, n, ref, ref_mse)[0]
            base_spp = base_spp or e_spp
            base_time = base_time or e_time
            print(f"| {scene} | {s} | {e_spp:.5f} | {base_spp / e_spp:.2f}x | {t:.2f} | {c / t_ind:.3f} | {n} | {e_time:.5f} | "
                  f"{base_time / e_time:.2f}x |", flush=True)
        print(f"| {scene} | (reference's RMSE, taken out) | {np.sqrt(ref_mse):.5f} | | | | | | |")


if __name__ == "__main__":
    main()
