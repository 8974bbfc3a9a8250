"""Persson's theory beside the paper-setting Fig. 1 (docs/persson.md), from fig1_paper.csv.

python docs/results/persson/summarise_fig1.py   (from the repository root; needs matplotlib)
Reads fig1_paper.csv (the persson_compare example on docs/results/paper/fig1/bem) and
docs/results/paper/fig1/bem/alpha.csv; writes fig1_summary.csv, fig1_summary.md and
fig1_alpha.png. The α window is the study's own: from 8 points in contact (area fraction
8/N²) to 1 % contact, on the ensemble-mean curve; Persson's k is in series with the bulk.
"""
import csv
import pathlib

from summarise import KAPPA_PERSSON, loglog_slope, rows

HERE = pathlib.Path(__file__).resolve().parent
ALPHA = HERE.parent / "paper" / "fig1" / "bem" / "alpha.csv"


def study_alpha():
    with open(ALPHA) as f:
        return {(int(r["n"]), float(r["hurst"])): r for r in csv.DictReader(f)}


def summarise(data, alphas):
    out = []
    for n, h in sorted({(r["n"], r["hurst"]) for r in data}):
        curve = [r for r in data if (r["n"], r["hurst"]) == (n, h)]
        window = [r for r in curve if 8 / n**2 <= r["area_bem"] <= 0.01]
        kappa = [r["kappa_bem_spectral"] for r in curve if 0.01 <= r["area_bem"] <= 0.05]
        study = alphas[(n, h)]
        out.append({
            "n": n, "hurst": h, "samples": int(curve[0]["samples"]),
            "alpha_bem": float(study["alpha"]),
            "alpha_bem_low": float(study["alpha_fit_low"]),
            "alpha_bem_high": float(study["alpha_fit_high"]),
            "alpha_theory": float(study["alpha_theory"]),
            "alpha_persson_series": loglog_slope([(r["pressure"], r["stiffness_persson_series"]) for r in window]),
            "alpha_bem_mean_points": loglog_slope([(r["pressure"], r["stiffness_bem"]) for r in window]),
            "window_points": len(window),
            "kappa_bem_spectral_1to5pct": sum(kappa) / len(kappa) if kappa else float("nan"),
            "kappa_persson": KAPPA_PERSSON,
            "k_bem_over_persson_min": min(r["stiffness_bem"] / r["stiffness_persson_series"] for r in window),
            "k_bem_over_persson_max": max(r["stiffness_bem"] / r["stiffness_persson_series"] for r in window),
        })
    return out


def markdown(table, n):
    lines = ["| H | α BEM (95 %) | α Persson + bulk | the paper (eq. 24, 1/(1+H), 1/3) | κ BEM (1–5 %) | k BEM / k Persson + bulk |",
             "|---|---|---|---|---|---|"]
    for t in (t for t in table if t["n"] == n):
        lines.append("| {hurst:g} | {alpha_bem:.3f} ({alpha_bem_low:.3f}–{alpha_bem_high:.3f}) | {alpha_persson_series:.3f} | {alpha_theory:.3f} | {kappa_bem_spectral_1to5pct:.2f} | {k_bem_over_persson_min:.2f} – {k_bem_over_persson_max:.2f} |".format(**t))
    return "\n".join(lines) + "\n"


def plot(table):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for n, colour in [(128, "C0"), (1024, "C3")]:
        ts = [t for t in table if t["n"] == n]
        hs = [t["hurst"] for t in ts]
        ax.errorbar(hs, [t["alpha_bem"] for t in ts],
                    yerr=[[t["alpha_bem"] - t["alpha_bem_low"] for t in ts],
                          [t["alpha_bem_high"] - t["alpha_bem"] for t in ts]],
                    fmt="o", color=colour, ms=4, capsize=2, label=f"BEM {n}² (60 samples, 95 %)")
        ax.plot(hs, [t["alpha_persson_series"] for t in ts], "s--", color=colour, ms=3, lw=1,
                label=f"Persson + bulk, {n}² spectra")
        ax.plot(hs, [t["alpha_theory"] for t in ts], ":", color=colour, lw=1.5,
                label=f"the paper: eq. (24), 1/(1+H), Hertz 1/3; {n}²")
    ax.set_xlabel("Hurst exponent H")
    ax.set_ylabel("α in k ∝ F^α (8 contacts … 1 % contact)")
    ax.set_title("Fig. 1 at the paper's setting: BEM, Persson's theory and the paper")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "fig1_alpha.png", dpi=110)


def main():
    table = summarise(rows("fig1_paper.csv"), study_alpha())
    with open(HERE / "fig1_summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    (HERE / "fig1_summary.md").write_text("".join(f"### {n}²\n\n" + markdown(table, n) + "\n" for n in (128, 256, 512, 1024)))
    plot(table)


if __name__ == "__main__":
    main()
