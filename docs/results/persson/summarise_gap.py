"""Generated table and plot of docs/persson.md's pressure–separation section, from the CSVs
of the persson_gap example (periodic BEM with the mean gap, beside Persson's theory).

python docs/results/persson/summarise_gap.py   (from the repository root; needs matplotlib)
Reads docs/results/persson/gap_*.csv; writes gap_summary.csv, gap_summary.md,
kappa_continuum.csv, kappa_continuum.md and gap.png.

Per sample, u0 of the BEM is the least-squares slope of -ū against ln p over a window of
p/(E* ḡ) (ḡ the spectral rms gradient); the same fit on Persson's ū (γ = 0.45) at the same
loads gives the theory's slope in that window, which is its asymptotic u0 = γ√π∫q²C w only
where every roughness scale is still out of contact. κ is A/A0 · E*ḡ/p averaged over the
window's loads, and the stiffness slope is d ln K/d ln p (Persson: 1 at low load).
Intervals: mean ± t(0.975, m-1)·sd/√m over the m samples.
"""
import csv
import math
import pathlib
import statistics

HERE = pathlib.Path(__file__).resolve().parent
GAMMA = 0.45  # of gap_persson in the CSVs
WINDOWS = [(3e-4, 3e-3), (1e-3, 1e-2), (3e-3, 3e-2)]
T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306,
        9: 2.262, 10: 2.228, 11: 2.201, 15: 2.131, 19: 2.093}


def rows():
    out = []
    for path in sorted(HERE.glob("gap_[0-9]*.csv")):
        with open(path) as f:
            for r in csv.DictReader(f):
                out.append({k: (int(v) if k in ("n", "seed", "iterations") else float(v)) for k, v in r.items()})
    return out


def slope(xs, ys):
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def interval(values):
    m = len(values)
    mean = statistics.fmean(values)
    if m < 2:
        return mean, float("nan")
    t = T975.get(m - 1, 1.96)
    return mean, t * statistics.stdev(values) / math.sqrt(m)


def per_sample(curve, window):
    lo, hi = window
    pts = [r for r in curve if lo <= r["pressure"] / r["rms_gradient"] <= hi * (1 + 1e-9)]
    if len(pts) < 3:
        return None
    ln_p = [math.log(r["pressure"]) for r in pts]
    return {
        "u0_bem": -slope(ln_p, [r["gap_bem"] for r in pts]),
        "u0_persson_window": -slope(ln_p, [r["gap_persson"] for r in pts]),
        "kappa_bem": statistics.fmean(r["area_bem"] * r["rms_gradient"] / r["pressure"] for r in pts),
        "stiffness_slope_bem": slope(ln_p, [math.log(r["stiffness_bem"]) for r in pts]),
        "k_bem_over_persson": statistics.fmean(r["stiffness_bem"] / r["stiffness_persson"] for r in pts),
        "gap_bem_over_persson": statistics.fmean(r["gap_bem"] / r["gap_persson"] for r in pts),
        "area_min": min(r["area_bem"] for r in pts),
        "area_max": max(r["area_bem"] for r in pts),
        "u0_per_gamma": pts[0]["u0_per_gamma"],
        "rms_height": pts[0]["rms_height"],
    }


def summarise(data):
    out = []
    keys = sorted({(r["n"], r["hurst"]) for r in data})
    for window in WINDOWS:
        for n, h in keys:
            samples = []
            for seed in sorted({r["seed"] for r in data if (r["n"], r["hurst"]) == (n, h)}):
                curve = [r for r in data if (r["n"], r["hurst"], r["seed"]) == (n, h, seed)]
                s = per_sample(curve, window)
                if s:
                    samples.append(s)
            if not samples:
                continue
            row = {"n": n, "hurst": h, "lambda_s_pixels": n / 64, "p_min": window[0], "p_max": window[1],
                   "samples": len(samples)}
            for k in samples[0]:
                mean, half = interval([s[k] for s in samples])
                row[k] = mean
                if k in ("u0_bem", "kappa_bem", "stiffness_slope_bem"):
                    row[k + "_ci95"] = half
            row["area_min"] = min(s["area_min"] for s in samples)
            row["area_max"] = max(s["area_max"] for s in samples)
            row["gamma_eff"] = row["u0_bem"] / row["u0_per_gamma"]
            row["gamma_eff_window"] = GAMMA * row["u0_bem"] / row["u0_persson_window"]
            out.append(row)
    return out


def markdown(table):
    lines = ["| p/(E*ḡ) | N (λ_s in px) | H | samples | BEM contact | u₀/h_rms BEM | u₀/h_rms Persson, window (γ=0.45) | u₀/h_rms Persson asymptotic γ=0.4 / 0.5 | γ_eff (asympt. / window) | ū BEM/Persson | κ BEM | dlnK/dlnp BEM | K BEM/Persson |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for t in table:
        hr = t["rms_height"]
        lines.append(
            "| {lo:g}–{hi:g} | {n} ({lam:g}) | {hurst:g} | {samples} | {amin:.2%}–{amax:.2%} | {u0:.3f} ± {u0ci:.3f} | {u0w:.3f} | {a:.3f} / {b:.3f} | {ge:.2f} / {gw:.2f} | {gr:.2f} | {k:.2f} ± {kci:.2f} | {s:.2f} ± {sci:.2f} | {kr:.2f} |".format(
                lo=t["p_min"], hi=t["p_max"], n=t["n"], lam=t["lambda_s_pixels"], hurst=t["hurst"],
                samples=t["samples"], amin=t["area_min"], amax=t["area_max"],
                u0=t["u0_bem"] / hr, u0ci=t["u0_bem_ci95"] / hr, u0w=t["u0_persson_window"] / hr,
                a=0.4 * t["u0_per_gamma"] / hr, b=0.5 * t["u0_per_gamma"] / hr,
                ge=t["gamma_eff"], gw=t["gamma_eff_window"], gr=t["gap_bem_over_persson"],
                k=t["kappa_bem"], kci=t["kappa_bem_ci95"], s=t["stiffness_slope_bem"],
                sci=t["stiffness_slope_bem_ci95"], kr=t["k_bem_over_persson"]))
    return "\n".join(lines) + "\n"


def kappa_continuum(table):
    """κ against the discretisation a/λ_s (a the pixel): per H and window, the weighted
    least-squares line through the grids' κ (weights 1/half-interval²), extrapolated to
    a/λ_s = 0 with its standard error — the form of Prodanov, Dapp & Müser's discretisation
    correction (linear in a/λ_s at small a/λ_s)."""
    out = []
    for window in WINDOWS:
        for h in sorted({t["hurst"] for t in table}):
            pts = [t for t in table if (t["p_min"], t["p_max"]) == window and t["hurst"] == h]
            if len(pts) < 2:
                continue
            xs = [1 / t["lambda_s_pixels"] for t in pts]
            ys = [t["kappa_bem"] for t in pts]
            ws = [1 / max(t["kappa_bem_ci95"] / 1.96, 1e-12) ** 2 for t in pts]
            sw = sum(ws)
            mx = sum(w * x for w, x in zip(ws, xs)) / sw
            my = sum(w * y for w, y in zip(ws, ys)) / sw
            sxx = sum(w * (x - mx) ** 2 for w, x in zip(ws, xs))
            b = sum(w * (x - mx) * (y - my) for w, x, y in zip(ws, xs, ys)) / sxx
            a = my - b * mx
            se = math.sqrt(1 / sw + mx**2 / sxx)
            out.append({"hurst": h, "p_min": window[0], "p_max": window[1], "grids": len(pts),
                        "kappa_continuum": a, "kappa_continuum_se": se, "slope_per_a_over_lambda_s": b,
                        "kappa_by_grid": " / ".join(f"{t['kappa_bem']:.2f}" for t in pts),
                        "lambda_s_pixels": " / ".join(f"{t['lambda_s_pixels']:g}" for t in pts)})
    return out


def kappa_markdown(rows):
    lines = ["| p/(E*ḡ) | H | λ_s in px | κ BEM per grid | κ at a/λ_s → 0 (± s.e.) | dκ/d(a/λ_s) |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| {lo:g}–{hi:g} | {h:g} | {lam} | {k} | {a:.2f} ± {se:.2f} | {b:.1f} |".format(
            lo=r["p_min"], hi=r["p_max"], h=r["hurst"], lam=r["lambda_s_pixels"], k=r["kappa_by_grid"],
            a=r["kappa_continuum"], se=r["kappa_continuum_se"], b=r["slope_per_a_over_lambda_s"]))
    return "\n".join(lines) + "\n"


def main():
    data = rows()
    table = summarise(data)
    with open(HERE / "gap_summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    (HERE / "gap_summary.md").write_text(markdown(table))
    kappa = kappa_continuum(table)
    with open(HERE / "kappa_continuum.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(kappa[0]))
        w.writeheader()
        w.writerows(kappa)
    (HERE / "kappa_continuum.md").write_text(kappa_markdown(kappa))
    plot(data)


def plot(data):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    n = max(r["n"] for r in data)
    for h, c in ((0.3, "C0"), (0.8, "C1")):
        curves = [r for r in data if r["n"] == n and r["hurst"] == h]
        # The loads are the same list for every sample (their mean pressures agree to
        # rounding): grouped by their logarithm to 6 digits.
        level = lambda r: round(math.log10(r["pressure"]), 6)
        ps = sorted({level(r) for r in curves})
        mean = lambda key, p: statistics.fmean(r[key] / r["rms_height"] for r in curves if level(r) == p)
        meank = lambda key, p: statistics.fmean(r[key] for r in curves if level(r) == p)
        pressures = [10**p for p in ps]
        ax1.semilogx(pressures, [mean("gap_bem", p) for p in ps], "o", color=c, ms=4, label=f"BEM H={h:g}")
        ax1.semilogx(pressures, [mean("gap_persson", p) for p in ps], "-", color=c, label=f"Persson γ={GAMMA} H={h:g}")
        ax2.loglog(pressures, [meank("stiffness_bem", p) for p in ps], "o", color=c, ms=4, label=f"BEM H={h:g}")
        ax2.loglog(pressures, [meank("stiffness_persson", p) for p in ps], "-", color=c, label=f"Persson H={h:g}")
    ax1.set_xlabel("p / E*")
    ax1.set_ylabel("ū / h_rms")
    ax1.set_title(f"mean separation, periodic {n}², roll-off 4, cut-off 64")
    ax1.legend(fontsize=8)
    ax2.set_xlabel("p / E*")
    ax2.set_ylabel("K A₀ / (E* L)")
    ax2.set_title("interfacial stiffness K = −dp/dū (BEM: frozen set)")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "gap.png", dpi=110)


if __name__ == "__main__":
    main()
