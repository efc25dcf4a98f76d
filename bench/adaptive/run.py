#!/usr/bin/env python3
"""Time to reach an RMSE with and without adaptive sampling (--target-error), against a high-spp reference.

  $PY bench/adaptive/run.py [--candela build/bin/candela] [--res 64] [--ref-spp 4096] [--threads 2]
                            [--scenes cornell,veach-mis] [--cache /tmp/candela-adaptive-bench]

Per scene: a reference (independent sampler, seed 1000, --ref-spp, cached); plain renders at
16..1024 spp; adaptive renders at target errors 0.4..0.025 (at least 16 spp per pixel, at most 4096,
passes of 16). Each render's time is candela's own (its summary line: rendering only, decisions
included). RMSE = sqrt(MSE - MSE_ref) over pixels and channels, MSE_ref = c / ref_spp with
c = the mean of MSE x spp over the plain renders (the reference is a plain render at ref_spp).
The time (and the mean spp) to reach an RMSE is interpolated log-log along each curve. Prints Markdown tables.
"""
import argparse, os, sys
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchlib import SCENES, read_pfm, run_candela  # noqa: E402



def render(args, scene, out, extra):
    cmd = [args.candela, *SCENES[scene], "--width", str(args.res), "--height", str(args.res), "--threads",
           str(args.threads), "--sampler", "independent", "--out", out, *extra]
    return run_candela(cmd)


def time_at(curve, rmse):
    """log-log interpolation of time at `rmse` along [(time, rmse)]; None outside the curve."""
    pts = sorted(curve)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - rmse) * (e1 - rmse) <= 0 and e0 != e1 and e0 > 0 and e1 > 0:
            a = (np.log(rmse) - np.log(e0)) / (np.log(e1) - np.log(e0))
            return float(np.exp(np.log(t0) + a * (np.log(t1) - np.log(t0))))
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--candela", default="build/bin/candela")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default="cornell,veach-mis")
    ap.add_argument("--cache", default="/tmp/candela-adaptive-bench")
    args = ap.parse_args()
    os.makedirs(args.cache, exist_ok=True)
    for scene in args.scenes.split(","):
        ref_path = f"{args.cache}/{scene}_{args.res}_ref{args.ref_spp}.pfm"
        if not os.path.exists(ref_path):
            render(args, scene, ref_path, ["--seed", "1000", "--spp-per-frame", "64", "--frames",
                                           str(args.ref_spp // 64)])
        ref = read_pfm(ref_path)
        plain, adaptive = [], []
        for spp in [16, 32, 64, 128, 256, 512, 1024]:
            out = f"{args.cache}/{scene}_plain{spp}.pfm"
            s, t = render(args, scene, out, ["--seed", "1", "--spp-per-frame", "16", "--frames", str(spp // 16)])
            plain.append((spp, s, t, float(np.mean((read_pfm(out) - ref) ** 2))))
        c = np.mean([mse * spp for spp, _, _, mse in plain])
        mse_ref = c / args.ref_spp
        for e in [0.4, 0.2, 0.1, 0.05, 0.025]:
            out = f"{args.cache}/{scene}_adaptive{e}.pfm"
            s, t = render(args, scene, out, ["--seed", "1", "--spp-per-frame", "16", "--frames", "256", "--target-error",
                                             str(e), "--adaptive-min-spp", "16"])
            adaptive.append((e, s, t, float(np.mean((read_pfm(out) - ref) ** 2))))
        rm = lambda mse: float(np.sqrt(max(mse - mse_ref, 1e-30)))
        print(f"\n### {scene} ({args.res}x{args.res}, reference {args.ref_spp} spp, {args.threads} threads)\n")
        print("| render | mean spp | time (s) | RMSE |\n|---|---|---|---|")
        for spp, s, t, mse in plain:
            print(f"| plain {spp} spp | {s:.1f} | {t:.2f} | {rm(mse):.5f} |")
        for e, s, t, mse in adaptive:
            print(f"| --target-error {e} | {s:.1f} | {t:.2f} | {rm(mse):.5f} |")
        pc = [(t, rm(mse)) for _, _, t, mse in plain]
        ac = [(t, rm(mse)) for _, _, t, mse in adaptive]
        ps = [(s, rm(mse)) for _, s, _, mse in plain]
        as_ = [(s, rm(mse)) for _, s, _, mse in adaptive]
        print("\n| RMSE | plain time (s) | adaptive time (s) | speed-up | plain spp | adaptive spp | spp ratio |\n"
              "|---|---|---|---|---|---|---|")
        fmt = lambda v: "n/a" if v is None else f"{v:.2f}"
        ratio = lambda a, b: "n/a" if not (a and b) else f"{a / b:.2f}x"
        for spp in [64, 256]:
            target = rm(next(mse for s_, _, _, mse in plain if s_ == spp))
            tp, ta = time_at(pc, target), time_at(ac, target)
            sp, sa = time_at(ps, target), time_at(as_, target)
            print(f"| {target:.5f} (plain {spp} spp) | {fmt(tp)} | {fmt(ta)} | {ratio(tp, ta)} | {fmt(sp)} | {fmt(sa)} "
                  f"| {ratio(sp, sa)} |")


if __name__ == "__main__":
    main()
