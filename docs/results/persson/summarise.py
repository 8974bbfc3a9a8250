"""Generated tables and plot of docs/persson.md from the CSVs of the persson_compare example.

python docs/results/persson/summarise.py   (from the repository root; needs matplotlib)
Writes docs/results/persson/summary.csv, summary.md and persson.png.
"""
import csv
import math
import pathlib

HERE = pathlib.Path(__file__).resolve().parent
KAPPA_PERSSON = math.sqrt(8 / math.pi)


def rows(name):
    with open(HERE / name) as f:
        return [{k: (float(v) if k != "n" else int(v)) for k, v in r.items()} for r in csv.DictReader(f)]


def loglog_slope(points):
    """Least-squares slope of log y against log x."""
    xs = [math.log(x) for x, _ in points]
    ys = [math.log(y) for _, y in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def summarise(data):
    out = []
    for key in sorted({(r["n"], r["hurst"]) for r in data}):
        curve = [r for r in data if (r["n"], r["hurst"]) == key]
        # kappa where the BEM contact fraction is between 1 % and 5 %
        window = [r for r in curve if 0.01 <= r["area_bem"] <= 0.05]
        kap_s = sum(r["kappa_bem_spectral"] for r in window) / len(window) if window else float("nan")
        kap_fd = sum(r["kappa_bem_fd"] for r in window) / len(window) if window else float("nan")
        # stiffness against load: BEM and Persson (in series with the bulk) at 0.1-1 % contact
        low = [r for r in curve if 0.001 <= r["area_bem"] <= 0.01]
        slope_bem = loglog_slope([(r["pressure"], r["stiffness_bem"]) for r in low]) if len(low) > 1 else float("nan")
        slope_p = loglog_slope([(r["pressure"], r["stiffness_persson_series"]) for r in low]) if len(low) > 1 else float("nan")
        ratio = [r["stiffness_bem"] / r["stiffness_persson_series"] for r in low]
        out.append({
            "n": key[0], "hurst": key[1], "samples": int(curve[0]["samples"]),
            "rms_gradient_spectral": curve[0]["rms_gradient_spectral"],
            "kappa_bem_spectral_1to5pct": kap_s, "kappa_bem_fd_1to5pct": kap_fd,
            "kappa_persson": KAPPA_PERSSON,
            "alpha_bem_0.1to1pct": slope_bem, "alpha_persson_series_0.1to1pct": slope_p,
            "k_bem_over_persson_min": min(ratio) if ratio else float("nan"),
            "k_bem_over_persson_max": max(ratio) if ratio else float("nan"),
            "u0_persson": curve[0]["u0_persson"],
        })
    return out


def main():
    data = rows("fig2_512.csv") + rows("fig2_1024.csv")
    table = summarise(data)
    with open(HERE / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    lines = ["| N | H | samples | ḡ (spectral) | κ BEM, ḡ spectral | κ BEM, ḡ f.d. | α BEM | α Persson + bulk | k BEM / k Persson + bulk |",
             "|---|---|---|---|---|---|---|---|---|"]
    for t in table:
        lines.append("| {n} | {hurst:g} | {samples} | {rms_gradient_spectral:.3f} | {kappa_bem_spectral_1to5pct:.2f} | {kappa_bem_fd_1to5pct:.2f} | {a:.3f} | {b:.3f} | {lo:.2f} – {hi:.2f} |".format(
            a=t["alpha_bem_0.1to1pct"], b=t["alpha_persson_series_0.1to1pct"],
            lo=t["k_bem_over_persson_min"], hi=t["k_bem_over_persson_max"], **t))
    (HERE / "summary.md").write_text("\n".join(lines) + "\n")
    plot(data)


def plot(data):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    colours = {-1.0: "C0", 0.0: "C1", 1.0: "C2", 2.0: "C3", 3.0: "C4"}
    curves = [r for r in data if r["n"] == 1024]
    for h, c in colours.items():
        rs = [r for r in curves if r["hurst"] == h]
        p = [r["pressure"] for r in rs]
        ax1.loglog(p, [r["area_bem"] for r in rs], "o", color=c, ms=3, label=f"BEM H={h:g}")
        ax1.loglog(p, [r["area_persson"] for r in rs], "-", color=c, lw=1)
        ax2.loglog(p, [r["stiffness_bem"] for r in rs], "o", color=c, ms=3, label=f"BEM H={h:g}")
        ax2.loglog(p, [r["stiffness_persson_series"] for r in rs], "-", color=c, lw=1)
    ax1.set_xlabel("p / E*  (ḡ_fd = 1)")
    ax1.set_ylabel("A / A0")
    ax1.set_title("contact area: BEM 1024² (dots), Persson 2001 (lines)")
    ax2.set_xlabel("F / (E* L²)")
    ax2.set_ylabel("k / (E* L)")
    ax2.set_title("stiffness: BEM (dots), Persson 2007 + bulk (lines)")
    ax1.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "persson.png", dpi=110)


if __name__ == "__main__":
    main()
