#!/usr/bin/env python3
"""Time to a given error, candela's samplers against Mitsuba 3's, in one sitting.

  nice -n 5 $PY bench/samplers/time_to_error.py [--scene cornell] [--res 128] [--ref-spp 16384] [--threads 2]
        [--seeds 2] [--levels 64,256,1024] [--target 0] [--candela build/bin/candela]

$PY is the reference venv's python (/root/.cache/candela-ref/venv/bin/python): Mitsuba 3 renders
in this process through ../shared/tools/mitsuba_render.py (llvm_ad_rgb, warm-up pass untimed,
so JIT compilation is not counted), candela as a subprocess (its summary line's render time, no
start-up or loading). Scene (--scene): cornell, veach-mis or caustics (scenes/*/scene.xml) at
width --res (height by the scene's aspect), unbounded depth, box filter;
Mitsuba's sampler is switched by a copy of the XML whose <sampler> type is the one measured.

Reference: Mitsuba llvm_ad_rgb, independent sampler, --ref-spp, seed 1000 (cached in --cache).
For each renderer and sampler, and each spp level N (rounded as the sampler needs: p^2 for
orthogonal), --seeds renders; RMSE(N) = sqrt(mean MSE over seeds - MSE_ref), MSE_ref the
reference's own expected MSE (Mitsuba independent's MSE at the first level times N / ref_spp).
Time per sample: the fastest render time over seeds and levels, per sample. The spp needed for
the target error E is interpolated on log RMSE against log N between the bracketing levels
(extrapolated from the last two when outside), and the time to E = that spp x time per spp.
E defaults to candela independent's RMSE at the last level. --table-only re-prints the table of
the last run (its rows.json in --cache), e.g. with another --target; --retime R adds R rounds of
timing in which every renderer and sampler renders ~256 spp in turn (the least time per spp seen
is kept), so that a load that changed during the run does not favour one renderer. Stratified samplers render one
complete set of N in candela (sample_count = N); Mitsuba renders in passes of 64 (the tool's
bound on llvm memory; 49 for orthogonal), each pass its own complete set, as its renders would.
Wall times on a shared machine vary by +-30%: read the time columns with that in mind.
--clamp C measures the error of both images clipped to [0, C] per channel (C = 1: the error a
display shows, where everything above white is white). On scenes whose error is dominated by
rare very bright samples (the Veach MIS plates, caustics) the unclipped RMSE of a few seeds does
not fall steadily with the samples, so no time to an error can be read from it; clipped, it can.
"""
import argparse, json, math, os, re, sys
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchlib import read_pfm, run_candela  # noqa: E402

# The Mitsuba 3 reference tools beside the repository: a developer aid outside it, needed by this
# benchmark only (no test or build step runs it).
TOOLS = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "tools"))
# name -> (XML, height / width): the XMLs take $width and $height (the Cornell box's $res sets both).
XMLS = {"cornell": ("scenes/cornell-box/scene.xml", 1.0), "veach-mis": ("scenes/veach-mis/scene.xml", 2 / 3),
        "caustics": ("scenes/caustics/scene.xml", 0.75)}
CANDELA = ["independent", "sobol", "zsobol", "orthogonal"]
MITSUBA = ["independent", "stratified", "multijitter", "ldsampler", "orthogonal"]



def next_square_prime(n):
    p = 2
    while p * p < n or any(p % d == 0 for d in range(2, int(math.isqrt(p)) + 1)):
        p += 1
    return p * p


def level(renderer, sampler, n):
    if sampler != "orthogonal":
        return n
    if renderer == "mitsuba" and n > 49:
        return 49 * round(n / 49)  # passes of 49 (7^2)
    return next_square_prime(n)


def candela_render(args, sampler, seed, spp, out):
    cmd = [args.candela, XMLS[args.scene][0], "--width", str(args.res), "--height", str(height(args)), "--threads", str(args.threads),
           "--sampler", sampler, "--seed", str(seed), "--sample-count", str(spp), "--spp-per-frame", str(spp),
           "--frames", "1", "--out", out]
    t = run_candela(cmd)[1]
    return read_pfm(out), t


def height(args):
    return max(1, round(args.res * XMLS[args.scene][1]))


def mitsuba_scene(args, sampler):
    """A copy of the scene's XML with the sampler's type switched, its mesh paths made absolute."""
    xml = XMLS[args.scene][0]
    src = open(xml).read()
    base = os.path.dirname(os.path.abspath(xml))
    src = re.sub(r'value="([^"/]+\.obj)"', lambda m: f'value="{base}/{m.group(1)}"', src)
    src = src.replace('<sampler type="independent">', f'<sampler type="{sampler}">')
    path = os.path.join(args.cache, f"{args.scene}_{sampler}.xml")
    with open(path, "w") as f:
        f.write(src)
    return path


def mitsuba_render(args, sampler, seed, spp):
    import mitsuba_render as mr
    per_pass = 49 if sampler == "orthogonal" else min(64, spp)
    img, info = mr.render(mitsuba_scene(args, sampler), variant="llvm_ad_rgb", spp=spp, seed=seed, threads=args.threads,
                          spp_per_pass=per_pass,
                          defines={"width": str(args.res), "height": str(height(args))}, quiet=True, warmup=True)
    return np.asarray(img, dtype=np.float64)[..., :3], float(info["render_s"])


def sq_err(args, img, ref):
    """Mean squared error over pixels and channels, both images clipped to [0, --clamp] if set."""
    if args.clamp > 0:
        img, ref = np.clip(img, 0, args.clamp), np.clip(ref, 0, args.clamp)
    return np.mean((img - ref) ** 2)


def curve(args, renderer, sampler, ref, ref_mse):
    """[(spp, RMSE)] over the levels, ref_mse taken out, and the time per spp (s, whole image)."""
    pts, per_spp = [], math.inf
    for n in args.levels:
        n = level(renderer, sampler, n)
        mse = []
        for seed in range(1, args.seeds + 1):
            if renderer == "candela":
                img, t = candela_render(args, sampler, seed, n, f"{args.cache}/c_{sampler}_{n}_{seed}.pfm")
            else:
                img, t = mitsuba_render(args, sampler, seed, n)
            mse.append(sq_err(args, img, ref))
            per_spp = min(per_spp, t / n)
        pts.append((n, math.sqrt(max(np.mean(mse) - ref_mse, 1e-30))))
        print(f"  {renderer} {sampler} {n} spp: RMSE {pts[-1][1]:.5f}", file=sys.stderr, flush=True)
    return pts, per_spp


def spp_for(pts, e):
    """spp at which RMSE reaches e: log-log interpolation between the bracketing levels, else
    extrapolation from the nearest two."""
    k = 0
    while k + 2 < len(pts) and pts[k + 1][1] > e:
        k += 1
    (n0, e0), (n1, e1) = pts[k], pts[k + 1]
    a = math.log(e1 / e0) / math.log(n1 / n0)
    return n0 * math.exp(math.log(e / e0) / a) if a < 0 else math.nan


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--candela", default="build/bin/candela")
    ap.add_argument("--scene", choices=sorted(XMLS), default="cornell")
    ap.add_argument("--res", type=int, default=128, help="image width (the height follows the scene's aspect)")
    ap.add_argument("--ref-spp", type=int, default=16384)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--levels", default="64,256,1024")
    ap.add_argument("--target", type=float, default=0, help="RMSE to reach (0: candela independent's at the last level)")
    ap.add_argument("--candela-samplers", default=",".join(CANDELA))
    ap.add_argument("--mitsuba-samplers", default=",".join(MITSUBA))
    ap.add_argument("--cache", default="")
    ap.add_argument("--clamp", type=float, default=0, help="clip both images to [0, C] before the error (0: off)")
    ap.add_argument("--table-only", action="store_true")
    ap.add_argument("--retime", type=int, default=0, metavar="R",
                    help="R more timing rounds over the last run's rows (interleaved), then the table")
    args = ap.parse_args()
    args.levels = [int(x) for x in args.levels.split(",")]
    args.cache = args.cache or f"/tmp/candela-tte-bench/{args.scene}"
    os.makedirs(args.cache, exist_ok=True)
    if args.table_only or args.retime:
        d = json.load(open(f"{args.cache}/rows.json"))
        sys.path.insert(0, TOOLS)
        for _ in range(args.retime):
            retime(args, d["rows"])
        with open(f"{args.cache}/rows.json", "w") as f:
            json.dump(d, f)
        print_table(args, d["rows"], d["ref_rmse"] ** 2)
        return
    sys.path.insert(0, TOOLS)
    ref_path = f"{args.cache}/ref_{args.scene}_{args.res}_{args.ref_spp}.npy"
    if not os.path.exists(ref_path):
        print(f"reference: Mitsuba independent, {args.ref_spp} spp ...", file=sys.stderr, flush=True)
        ref, _ = mitsuba_render(args, "independent", 1000, args.ref_spp)
        np.save(ref_path, ref)
    ref = np.load(ref_path)
    # The reference's own expected MSE per sample: the independent sampler's MSE x N is constant,
    # so MSE_ref = MSE_ind(N) x N / ref_spp; measured at the first level (Mitsuba, noise of the
    # reference included, hence ref_spp + N).
    n0 = args.levels[0]
    mse_ind = np.mean([sq_err(args, mitsuba_render(args, "independent", 500 + s, n0)[0], ref) for s in range(args.seeds)])
    ref_mse = mse_ind * n0 / (args.ref_spp + n0)
    rows = []
    for renderer, samplers in (("candela", args.candela_samplers), ("mitsuba", args.mitsuba_samplers)):
        for s in samplers.split(","):
            if not s:
                continue
            pts, per_spp = curve(args, renderer, s, ref, ref_mse)
            rows.append((renderer, s, pts, per_spp))
    with open(f"{args.cache}/rows.json", "w") as f:
        json.dump({"rows": rows, "ref_rmse": math.sqrt(ref_mse)}, f)
    print_table(args, rows, ref_mse)


def retime(args, rows):
    """One round of timing, every renderer and sampler in turn (so that both see the same load):
    a render of about 256 spp; the time per spp kept is the least seen."""
    for row in rows:
        renderer, sampler = row[0], row[1]
        n = level(renderer, sampler, 256)
        if renderer == "candela":
            _, t = candela_render(args, sampler, 99, n, f"{args.cache}/t_{sampler}.pfm")
        else:
            _, t = mitsuba_render(args, sampler, 99, n)
        row[3] = min(row[3], t / n)
        print(f"  time {renderer} {sampler}: {args.res * height(args) * n / t * 1e-6:.2f} Msamples/s", file=sys.stderr, flush=True)


def print_table(args, rows, ref_mse):
    target = args.target or dict(((r, s), p) for r, s, p, _ in rows)[("candela", "independent")][-1][1]
    base = None
    print(f"{args.scene} {args.res}x{height(args)}, {args.threads} threads, {args.seeds} seeds per level, reference Mitsuba "
          f"independent {args.ref_spp} spp (its RMSE {math.sqrt(ref_mse):.5f}, taken out); "
          f"target RMSE {target:.5f}" + (f", images clipped to [0, {args.clamp:g}]" if args.clamp > 0 else "") + "\n")
    lv = " | ".join(f"RMSE @{n}" for n in args.levels)
    print(f"| renderer | sampler | Msamples/s | {lv} | spp to target | time to target (s) | speed-up |")
    print("|---|---|---|" + "---|" * len(args.levels) + "---|---|---|")
    for renderer, s, pts, per_spp in rows:
        n = spp_for(pts, target)
        t = n * per_spp
        base = base or t
        msps = args.res * height(args) / per_spp * 1e-6
        es = " | ".join(f"{e:.5f}" + (f" ({m} spp)" if m != lvl else "") for (m, e), lvl in zip(pts, args.levels))
        print(f"| {renderer} | {s} | {msps:.2f} | {es} | {n:.0f} | {t:.2f} | {base / t:.2f}x |", flush=True)


if __name__ == "__main__":
    main()
