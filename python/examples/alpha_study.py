"""An α study: the exponent α of k ∝ F^α against the Hurst exponent H, by the method of
dimensionality reduction on rough lines, compared with the paper's eq. (6) and (24).

    python alpha_study.py [FOLDER]

Runs 5 values of H × 60 lines of 4096 points in FOLDER (default alpha-study): the same
checkpoint folder as `asperity study alpha --method mdr --n 4096 --hurst -0.5:1.5:0.5
--samples 60 --out FOLDER`, so either can resume the other (interrupt with Ctrl-C and run
again). Writes FOLDER/alpha_vs_h.png.
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import asperity

folder = sys.argv[1] if len(sys.argv) > 1 else "alpha-study"
result = asperity.study_alpha(method="mdr", n=4096, hurst="-0.5:1.5:0.5", samples=60,
                              out=folder, progress=True)

print(f"{'H':>6} {'alpha':>8} {'2.5 %':>8} {'97.5 %':>8} {'theory':>8}")
for row in result.rows:
    print(f"{row['hurst']:6.2f} {row['alpha']:8.4f} {row['alpha_low']:8.4f} "
          f"{row['alpha_high']:8.4f} {row['alpha_theory']:8.4f}")

fig, ax = plt.subplots(figsize=(6, 4))
ax.errorbar(result.hurst, result.alpha,
            yerr=[result.alpha - result.alpha_low, result.alpha_high - result.alpha],
            fmt="o", capsize=3, label="MDR, N = 4096 (spread over lines)")
# Theory: eq. (24), (1 + log2 N)/(3 + log2 N), for H ≤ 0; eq. (6), 1/(1 + H), above.
h = np.linspace(-0.5, 1.5, 81)
white = (1 + np.log2(4096)) / (3 + np.log2(4096))
ax.plot(h, np.where(h <= 0, white, 1 / (1 + np.maximum(h, 1e-12))), "k--",
        label="theory: (24) for H ≤ 0, (6) above")
ax.plot(result.hurst, result.alpha_theory, "kx", label="theory at the study's H")
ax.set(xlabel="Hurst exponent H", ylabel="α of k ∝ F^α")
ax.legend()
fig.tight_layout()
path = os.path.join(folder, "alpha_vs_h.png")
fig.savefig(path, dpi=100)
print(f"wrote {path}")
