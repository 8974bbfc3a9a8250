#!/usr/bin/env python3
"""Pull-off of adhesive rough surfaces across H and rms slope (issue 38, item 4; docs/adhesion.md).

Each case is one periodic rough surface (`asperity surface --n N --hurst H --rolloff 4
--rms-slope S --seed K`, L = 1, E* = 1) pressed into an elastic half-space with the
exponential potential (`asperity bem --boundary periodic --work-of-adhesion W
--adhesion-range RHO --adhesion-model exponential`): approached in 12 equal steps to
d = 1.5 rms heights below first touch, then retracted to pull-off. Recorded per case: the
force-controlled and displacement-controlled pull-offs, the greatest attached fraction and
force (a negative greatest force: the surface pulls at every point of the path, and the
least force is at its deepest point), the CPU time of the run, and the hysteresis: the largest gap between
the approach's force and the retraction's at the approach's indentations, over the
largest force. Writes cases.csv (one row per surface), summary.csv (mean and 95 % t
interval over the seeds of each H and slope), loops.csv (the force-approach loops of seed
1 at --loop-slope, and the hysteretic case: the same surface of H = 0.8 under Pohrt &
Popov's pixel criterion with --pixel-w, vanishing range and irreversible release) and
adhesion_rough.png. Only the asperity binary is needed (numpy and matplotlib to
summarise and draw):

  python docs/results/adhesion_rough/study.py --asperity target/release/asperity \
      --out docs/results/adhesion_rough
"""
import argparse
import csv
import json
import os
import resource
import subprocess
import tempfile

import numpy as np

# Student t quantiles (two-sided 95 %) by degrees of freedom.
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262}


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_case(args, tmp, hurst, slope, seed, law=None):
    surface = os.path.join(tmp, "s.npy")
    subprocess.run([args.asperity, "surface", "--n", str(args.n), "--hurst", str(hurst),
                    "--rolloff", "4", "--rms-slope", str(slope), "--seed", str(seed),
                    "--out", surface, "--force"], check=True, capture_output=True)
    h = np.load(surface)
    rms = float(h.std())
    path = [1.5 * rms * k / 12 for k in range(13)]
    out = os.path.join(tmp, "a.csv")
    step = (path[-1] + args.rho) / args.retract_steps
    cpu = child_cpu()
    model = ["--work-of-adhesion", str(args.w), "--adhesion-range", str(args.rho),
             "--adhesion-model", "exponential"]
    if law == "pixel":  # Pohrt & Popov's criterion: vanishing range, irreversible release
        model = ["--work-of-adhesion", str(args.pixel_w)]
        step = path[-1] / args.retract_steps
    subprocess.run([args.asperity, "bem", "--surface", surface, "--boundary", "periodic",
                    *model, "--indentations", ",".join(repr(d) for d in path),
                    "--retract-step", repr(step), "--out", out, "--force"],
                   check=True, capture_output=True)
    cpu = child_cpu() - cpu
    rows = list(csv.DictReader(open(out)))
    record = json.load(open(out + ".json"))["adhesion"]
    d = np.array([float(r["indentation"]) for r in rows])
    f = np.array([float(r["force"]) for r in rows])
    back = np.array([r["branch"] == "retract" for r in rows])
    # The retraction from the deepest point, its force at the approach's indentations.
    rd, rf = np.concatenate([[d[~back][-1]], d[back]]), np.concatenate([[f[~back][-1]], f[back]])
    order = np.argsort(rd)
    at = np.interp(d[~back], rd[order], rf[order])
    inside = d[~back] >= rd.min()
    hysteresis = float(np.max((f[~back] - at)[inside]) / np.max(np.abs(f)))
    pull = record["pull_off"]
    return {"hurst": hurst, "rms_slope": slope, "seed": seed, "rms_height": rms,
            "zone_resolution": record["zone_resolution"],
            "pull_off_force": pull["force_controlled"]["force"],
            "pull_off_indentation": pull["force_controlled"]["indentation"],
            "pull_off_force_displacement": pull["displacement_controlled"]["force"],
            "max_area_fraction": max(float(r["area_fraction"]) for r in rows),
            "max_force": float(f.max()), "hysteresis": hysteresis, "rows": len(rows),
            "cpu_seconds": cpu}, (d, f, back)


def summarise(cases):
    groups = {}
    for c in cases:
        groups.setdefault((c["hurst"], c["rms_slope"]), []).append(c)
    out = []
    for (hurst, slope), members in sorted(groups.items()):
        row = {"hurst": hurst, "rms_slope": slope, "samples": len(members)}
        for name in ["pull_off_force", "hysteresis", "max_area_fraction", "rms_height"]:
            v = np.array([m[name] for m in members])
            half = T95.get(len(v) - 1, 2.0) * v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else 0
            row[name] = float(v.mean())
            row[name + "_low"], row[name + "_high"] = float(v.mean() - half), float(v.mean() + half)
        out.append(row)
    return out


def write_csv(path, rows):
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)


def draw(args, summary, loops):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12.8, 4.8))
    colors = {h: plt.get_cmap("viridis")(i / max(len(args.hursts) - 1, 1))
              for i, h in enumerate(args.hursts)}
    scale = args.w / args.rho  # the potential's greatest tension σ_m
    for h in args.hursts:
        rows = [r for r in summary if r["hurst"] == h]
        x = np.array([r["rms_slope"] for r in rows])
        y = np.array([-r["pull_off_force"] / scale for r in rows])
        lo = np.array([-r["pull_off_force_high"] / scale for r in rows])
        hi = np.array([-r["pull_off_force_low"] / scale for r in rows])
        ax.errorbar(x, y, yerr=[y - lo, hi - y], fmt="-o", color=colors[h], capsize=3,
                    label=f"H = {h}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("rms slope h'")
    ax.set_ylabel("pull-off stress −F_c/(A₀σ_m)")
    ax.set_title(f"{args.n}², exponential law, w = {args.w:g}, ρ = {args.rho:g} (E* = L = 1)")
    ax.legend()
    for (h, slope), (d, f, back) in loops.items():
        c = colors.get(h, "red")
        name = (f"H = {h}, h' = {slope}" if h in colors
                else f"H = 0.8, h' = {slope}, pixel criterion w = {args.pixel_w:g}")
        bx.plot(d[~back], f[~back], "-o", color=c, markersize=3, label=name)
        rd = np.concatenate([[d[~back][-1]], d[back]])
        rf = np.concatenate([[f[~back][-1]], f[back]])
        bx.plot(rd, rf, "--", color=c)
        for xs, ys in [(d[~back], f[~back]), (rd, rf)]:
            k = len(xs) // 2
            if k + 1 < len(xs):
                bx.annotate("", xy=(xs[k + 1], ys[k + 1]), xytext=(xs[k], ys[k]),
                            arrowprops={"arrowstyle": "-|>", "color": c})
        low = int(np.argmin(f))
        bx.plot([d[low]], [f[low]], "s", color="k", markersize=5)
    bx.axhline(0, color="grey", lw=0.5)
    bx.set_xlabel("indentation d (below first touch)")
    bx.set_ylabel("force F (E*·L²)")
    bx.set_title("loops (seed 1): approach solid, retraction dashed, pull-off ■")
    bx.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "adhesion_rough.png"), dpi=110)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--asperity", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--n", type=int, default=128)
    p.add_argument("--hursts", type=float, nargs="+", default=[0.3, 0.5, 0.8])
    p.add_argument("--slopes", type=float, nargs="+", default=[0.05, 0.1, 0.2])
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--w", type=float, default=4e-6)
    p.add_argument("--rho", type=float, default=5e-4)
    p.add_argument("--retract-steps", type=int, default=80)
    p.add_argument("--loop-slope", type=float, default=0.05)
    p.add_argument("--pixel-w", type=float, default=1e-5)
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    cases, loops = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        for h in args.hursts:
            for s in args.slopes:
                for k in range(1, args.seeds + 1):
                    case, loop = run_case(args, tmp, h, s, k)
                    cases.append(case)
                    if k == 1 and s == args.loop_slope:
                        loops[(h, s)] = loop
                    print(json.dumps({x: case[x] for x in ["hurst", "rms_slope", "seed",
                                      "pull_off_force", "hysteresis", "cpu_seconds"]}),
                          flush=True)
                    write_csv(os.path.join(args.out, "cases.csv"), cases)
        pixel, loop = run_case(args, tmp, 0.8, args.loop_slope, 1, law="pixel")
        loops[("pixel criterion", args.loop_slope)] = loop
        print(json.dumps({x: pixel[x] for x in ["pull_off_force", "hysteresis", "cpu_seconds"]}))
        with open(os.path.join(args.out, "pixel_case.json"), "w") as fh:
            json.dump({**pixel, "law": "pixel criterion", "w": args.pixel_w}, fh, indent=1)
    summary = summarise(cases)
    write_csv(os.path.join(args.out, "summary.csv"), summary)
    with open(os.path.join(args.out, "loops.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["hurst", "rms_slope", "branch", "indentation", "force"])
        for (h, s), (d, f, back) in loops.items():
            for di, fi, bi in zip(d, f, back):
                w.writerow([h, s, "retract" if bi else "path", repr(float(di)), repr(float(fi))])
    version = subprocess.run([args.asperity, "--version"], capture_output=True, text=True)
    with open(os.path.join(args.out, "run.json"), "w") as fh:
        json.dump({"asperity": version.stdout.strip(), "n": args.n, "hursts": args.hursts,
                   "slopes": args.slopes, "seeds": args.seeds, "w": args.w, "rho": args.rho,
                   "retract_steps": args.retract_steps,
                   "cpu_seconds": sum(c["cpu_seconds"] for c in cases),
                   "load_average": os.getloadavg()}, fh, indent=1)
    draw(args, summary, loops)


if __name__ == "__main__":
    main()
