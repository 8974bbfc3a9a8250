"""A BEM load sweep: contact stiffness and true contact area of a rough surface against the
normal force, plotted with matplotlib.

    python bem_load_sweep.py [OUT.png]

Generates a 128² self-affine surface (H = 0.8, roll-off at 4 wavelengths per side, unit rms
slope), presses it into an elastic half-space (E* = 1, free boundaries) at 16 mean
pressures from 1e-4 to 1e-1 E*, and plots k(F) and A/A0(F) on log-log axes. The sweep is
`asperity bem --nloads 16 --pmin 1e-4 --pmax 1e-1` with the same numbers.
"""

import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt
import numpy as np

import asperity

out = sys.argv[1] if len(sys.argv) > 1 else "bem_load_sweep.png"
surface = asperity.surface(128, hurst=0.8, rolloff=4, rms_slope=1.0, seed=1)
solver = asperity.Solver(surface, modulus=1.0, boundary="free")
sweep = solver.sweep(nloads=16, pmin=1e-4, pmax=1e-1, progress=True)

# The low-force exponent of k ∝ F^α over the first half of the sweep (paper eq. 3).
half = len(sweep) // 2
alpha = np.polyfit(np.log(sweep.force[:half]), np.log(sweep.stiffness[:half]), 1)[0]
print(f"{len(sweep)} loads, area fraction {sweep.area_fraction[0]:.2e} to "
      f"{sweep.area_fraction[-1]:.2e}, alpha at low force = {alpha:.3f}")

fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
left.loglog(sweep.force, sweep.stiffness, "o-")
left.set(xlabel="normal force F / E*  [length²]", ylabel="contact stiffness k / E*  [length]",
         title=f"frozen contact set, α ≈ {alpha:.2f} at low force")
right.loglog(sweep.force, sweep.area_fraction, "o-")
right.set(xlabel="normal force F / E*  [length²]", ylabel="area fraction A / A0",
          title="true contact area")
fig.tight_layout()
fig.savefig(out, dpi=100)
print(f"wrote {out}")
