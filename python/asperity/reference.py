"""Closed-form reference solutions: the library's ``asperity::reference``, by the same code.

Every model takes the effective modulus ``modulus`` E* (``1/E* = (1−ν₁²)/E₁ +
(1−ν₂²)/E₂``; :func:`asperity.effective_modulus` gives it from Young's modulus and
Poisson's ratio) in any consistent units, and its methods work elementwise on numbers or
numpy arrays (returning a float or an array of the same shape). Indentations ``d`` and
approaches are positive into the half-space; compressive forces are positive.

* :class:`Hertz` -- a sphere (paraboloid ``r²/2R``): ``F = 4/3 E* R^½ d^{3/2}``;
* :class:`FlatPunch` -- a flat cylinder of radius a: ``F = 2 E* a d``;
* :class:`Cone` -- ``f(r) = r tan θ``; :class:`PowerLaw` -- ``f(r) = c rⁿ`` (by the MDR);
* :class:`Westergaard` -- a periodic sinusoid pressed flat (``p* = π E* Δ/λ``);
* :class:`CattaneoMindlin` -- a Hertz contact under a tangential force (partial slip);
* :class:`Jkr`, :class:`Dmt`, :class:`Kendall` -- adhesive sphere and punch;
* :class:`MaugisDugdale` -- the adhesive sphere between DMT and JKR (a Dugdale cohesive
  zone), dimensionless, with the units of a given sphere (:meth:`MaugisDugdale.scales`);
* :class:`JohnsonSinusoid` -- Johnson's adhesive periodic sinusoid (JKR-type edges).

Example::

    >>> from asperity.reference import Hertz
    >>> h = Hertz(radius=1.0, modulus=1.0)
    >>> float(h.force(1e-2)), float(h.stiffness(1e-2))   # 4/3 · 10⁻³, 2 · 0.1
    (0.0013333333333333333, 0.2)
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as _np

from . import _asperity as _core

__all__ = ["Hertz", "FlatPunch", "Cone", "PowerLaw", "Westergaard", "CattaneoMindlin",
           "Jkr", "Dmt", "Kendall", "MaugisDugdale", "JohnsonSinusoid"]


def __dir__() -> list:
    """The public names only: the helpers this module imports are not part of it."""
    return sorted(__all__)


class _Model:
    _name = ""
    _params: Sequence[str] = ()

    def __init__(self, *args: float, **kwargs: float):
        values = dict(zip(self._params, args))
        values.update(kwargs)
        missing = [p for p in self._params if p not in values]
        extra = [k for k in values if k not in self._params]
        if missing or extra or len(args) > len(self._params):
            raise TypeError(f"{type(self).__name__}({', '.join(self._params)}): "
                            f"missing {missing}, unexpected {extra}")
        for name in self._params:
            setattr(self, name, float(values[name]))
        self._eval("__check__", 0.0, check=True)

    def _eval(self, method: str, x: Any, *scalars: float, check: bool = False) -> Any:
        params = [getattr(self, p) for p in self._params]
        if check:
            # The parameters are checked by the library (positive and finite) on any call.
            method = self._probe
        array = _np.asarray(x, dtype=_np.float64)
        out = _core.reference(self._name, params, method, [float(s) for s in scalars], array)
        return float(out) if array.ndim == 0 else out

    def __repr__(self) -> str:
        args = ", ".join(f"{p}={getattr(self, p)!r}" for p in self._params)
        return f"{type(self).__name__}({args})"


class Hertz(_Model):
    """A rigid sphere of ``radius`` R (paraboloid ``r²/2R``) on a half-space of ``modulus``
    E* (Hertz 1882; Johnson, *Contact Mechanics*, §4.2)."""

    _name, _params, _probe = "hertz", ("radius", "modulus"), "force"

    def force(self, indentation: Any) -> Any:
        """``F = 4/3 E* R^½ d^{3/2}``."""
        return self._eval("force", indentation)

    def contact_radius(self, indentation: Any) -> Any:
        """``a = √(R d)``."""
        return self._eval("contact_radius", indentation)

    def indentation(self, force: Any) -> Any:
        """``d = (3F / 4E*R^½)^{2/3}``."""
        return self._eval("indentation", force)

    def stiffness(self, indentation: Any) -> Any:
        """``k = dF/dd = 2 E* a``."""
        return self._eval("stiffness", indentation)

    def pressure(self, indentation: float, r: Any) -> Any:
        """``p(r) = (2E*/πR) √(a² − r²)`` inside the contact, 0 outside."""
        return self._eval("pressure", r, indentation)


class FlatPunch(_Model):
    """A rigid flat-ended cylinder of ``radius`` a: ``k = 2 E* a`` at any indentation."""

    _name, _params, _probe = "flat_punch", ("radius", "modulus"), "force"

    def force(self, indentation: Any) -> Any:
        """``F = 2 E* a d``."""
        return self._eval("force", indentation)

    def stiffness(self) -> float:
        """``k = 2 E* a``."""
        return self._eval("stiffness", 0.0)


class Cone(_Model):
    """A rigid cone ``f(r) = r tan θ`` (``slope`` = tan θ)."""

    _name, _params, _probe = "cone", ("slope", "modulus"), "force"

    def force(self, indentation: Any) -> Any:
        """``F = 2 E* d² / (π tan θ)``."""
        return self._eval("force", indentation)

    def contact_radius(self, indentation: Any) -> Any:
        """``a = 2d / (π tan θ)``."""
        return self._eval("contact_radius", indentation)

    def stiffness(self, indentation: Any) -> Any:
        """``k = 2 E* a``."""
        return self._eval("stiffness", indentation)


class PowerLaw(_Model):
    """A power-law indenter ``f(r) = c rⁿ`` (``coefficient`` c, ``exponent`` n > 0), by
    the MDR (Popov & Heß, ch. 3); Hertz is n = 2, c = 1/2R."""

    _name, _params, _probe = "power_law", ("coefficient", "exponent", "modulus"), "force"

    def force(self, indentation: Any) -> Any:
        """``F = 2 E* n/(n+1) d a``."""
        return self._eval("force", indentation)

    def contact_radius(self, indentation: Any) -> Any:
        """``a`` from ``d = κ(n) c aⁿ``, ``κ(n) = √π Γ(n/2+1)/Γ(n/2+½)``."""
        return self._eval("contact_radius", indentation)

    def stiffness(self, indentation: Any) -> Any:
        """``k = 2 E* a``."""
        return self._eval("stiffness", indentation)


class Westergaard(_Model):
    """Westergaard's periodic contact: a rigid sinusoid ``amplitude · cos(2πx/λ)`` of
    ``wavelength`` λ pressed with a mean pressure p̄ (Johnson, §13.2)."""

    _name, _params = "westergaard", ("wavelength", "amplitude", "modulus")
    _probe = "full_contact_pressure"

    def full_contact_pressure(self) -> float:
        """``p* = π E* Δ / λ``."""
        return self._eval("full_contact_pressure", 0.0)

    def contact_half_width(self, mean_pressure: Any) -> Any:
        """``a`` from ``p̄ = p* sin²(πa/λ)``."""
        return self._eval("contact_half_width", mean_pressure)

    def contact_fraction(self, mean_pressure: Any) -> Any:
        """``2a/λ``."""
        return self._eval("contact_fraction", mean_pressure)

    def indentation(self, mean_pressure: Any) -> Any:
        """``d = Δ r (1 − ln r)``, ``r = p̄/p*`` (relative to the mean elastic displacement,
        the convention of periodic boundaries)."""
        return self._eval("indentation", mean_pressure)

    def pressure(self, mean_pressure: float, x: Any) -> Any:
        """The pressure at distance ``x`` from a crest."""
        return self._eval("pressure", x, mean_pressure)


class CattaneoMindlin(_Model):
    """A Hertz contact (``radius``, ``modulus``) at indentation d under a tangential force
    Q ≤ μF: ``ratio`` = G*/E* (``2(1−ν)/(2−ν)`` for one Poisson's ratio), ``friction`` μ
    (Johnson, §7.2; Mindlin & Deresiewicz)."""

    _name, _params = "cattaneo_mindlin", ("radius", "modulus", "ratio", "friction")
    _probe = "no_slip_stiffness"

    def _eval(self, method: str, x: Any, *scalars: float, check: bool = False) -> Any:
        if check:
            scalars = (1.0,)
        return super()._eval(method, x, *scalars, check=check)

    def stick_radius(self, indentation: float, force: Any) -> Any:
        """``c = a (1 − Q/μF)^{1/3}``."""
        return self._eval("stick_radius", force, indentation)

    def displacement(self, indentation: float, force: Any) -> Any:
        """``u = μ (E*/G*) d [1 − (1 − Q/μF)^{2/3}]`` on loading."""
        return self._eval("displacement", force, indentation)

    def unloading_displacement(self, indentation: float, amplitude: float, force: Any) -> Any:
        """The displacement on unloading from ``amplitude`` Q* to Q."""
        return self._eval("unloading_displacement", force, indentation, amplitude)

    def no_slip_stiffness(self, indentation: float) -> float:
        """``2 G* a``."""
        return self._eval("no_slip_stiffness", 0.0, indentation)

    def dissipation(self, indentation: float, amplitude: Any) -> Any:
        """Energy dissipated per cycle of ``amplitude`` Q* (Mindlin & Deresiewicz)."""
        return self._eval("dissipation", amplitude, indentation)


class _Adhesive(_Model):
    _params = ("radius", "modulus", "work_of_adhesion")


class Jkr(_Adhesive):
    """Johnson–Kendall–Roberts: a sphere of ``radius`` R with ``work_of_adhesion`` Δγ,
    parametrised by the contact radius a (both branches)."""

    _name, _probe = "jkr", "force"

    def approach(self, contact_radius: Any) -> Any:
        """``δ = a²/R − √(2πaΔγ/E*)``."""
        return self._eval("approach", contact_radius)

    def force(self, contact_radius: Any) -> Any:
        """``F = 4E*a³/3R − √(8πΔγE*a³)``."""
        return self._eval("force", contact_radius)

    def contact_radius_at_force(self, force: Any) -> Any:
        """The stable branch's a at F (NaN below the force-controlled pull-off)."""
        return self._eval("contact_radius_at_force", force)

    def zero_force_radius(self) -> float:
        return self._eval("zero_force_radius", 0.0)

    def pull_off_force(self, control: str = "force") -> float:
        """``-3/2 πΔγR`` under ``control="force"``, ``-5/6 πΔγR`` under ``"displacement"``."""
        return self._eval(f"pull_off_force_{_control(control)}", 0.0)

    def pull_off_radius(self, control: str = "force") -> float:
        """``(9πΔγR²/8E*)^{1/3}`` (force control) or ``(πΔγR²/8E*)^{1/3}``."""
        return self._eval(f"pull_off_radius_{_control(control)}", 0.0)


def _control(control: str) -> str:
    if control not in ("force", "displacement"):
        raise ValueError(f"control must be 'force' or 'displacement', got {control!r}")
    return control


class Dmt(_Adhesive):
    """Derjaguin–Muller–Toporov: Hertz's shape plus the adhesive force ``-2πΔγR``."""

    _name, _probe = "dmt", "force"

    def approach(self, contact_radius: Any) -> Any:
        return self._eval("approach", contact_radius)

    def force(self, contact_radius: Any) -> Any:
        return self._eval("force", contact_radius)

    def pull_off_force(self) -> float:
        """``-2πΔγR``."""
        return self._eval("pull_off_force", 0.0)


class Kendall(_Adhesive):
    """Kendall's adhesive flat punch of ``radius`` a."""

    _name, _probe = "kendall", "force"

    def force(self, approach: Any) -> Any:
        return self._eval("force", approach)

    def pull_off_approach(self) -> float:
        return self._eval("pull_off_approach", 0.0)

    def pull_off_force(self) -> float:
        """``-√(8πΔγE*a³)``."""
        return self._eval("pull_off_force", 0.0)


class MaugisDugdale(_Model):
    """Maugis–Dugdale (Maugis 1992; Johnson & Greenwood 1997): a sphere with a constant
    adhesive stress σ₀ acting over the range h₀ = Δγ/σ₀ outside the contact, spanning DMT
    (λ → 0) and JKR (λ → ∞) by the Maugis parameter ``maugis_parameter`` λ = 2σ₀
    (R/πΔγK²)^{1/3}, K = 4E*/3. Dimensionless, as the library's
    ``asperity::reference::MaugisDugdale`` (the closed form the adhesive BEM is checked
    against): contact radius Ā = a (K/πΔγR²)^{1/3}, force P̄ = F/(πΔγR), approach
    Δ̄ = δ (K²/π²Δγ²R)^{1/3}; :meth:`scales` gives the units of a sphere.

    Examples
    --------
    >>> from asperity.reference import MaugisDugdale
    >>> round(MaugisDugdale(1e4).pull_off_force(), 2)     # JKR: -3/2
    -1.5
    >>> round(MaugisDugdale(1e-8).pull_off_force(), 3)    # DMT: -2
    -2.0
    """

    _name, _params, _probe = "maugis_dugdale", ("maugis_parameter",), "zone_ratio"

    def _curve(self, method: str, contact_radius: Any) -> Any:
        a = _np.asarray(contact_radius, dtype=_np.float64)
        if not (_np.isfinite(a).all() and (a > 0).all()):
            raise ValueError("contact_radius must be positive and finite")
        return self._eval(method, a)

    def force(self, contact_radius: Any) -> Any:
        """``P̄ = Ā³ − λĀ²[s + m² atan s]``, ``s = √(m² − 1)``, m = c/a from Maugis' energy
        balance."""
        return self._curve("force", contact_radius)

    def approach(self, contact_radius: Any) -> Any:
        """``Δ̄ = Ā² − (4/3)λĀs``."""
        return self._curve("approach", contact_radius)

    def zone_ratio(self, contact_radius: Any) -> Any:
        """m = c/a ≥ 1: the cohesive zone's outer radius over the contact radius."""
        return self._curve("zone_ratio", contact_radius)

    def pull_off_force(self, control: str = "force") -> float:
        """P̄ at pull-off: the least force (``control="force"``) or the force at the least
        approach (``"displacement"``); between −2 (DMT) and −3/2 (JKR, force control)."""
        return self._eval(f"pull_off_force_{_control(control)}", 0.0)

    def pull_off_radius(self, control: str = "force") -> float:
        """Ā at pull-off."""
        return self._eval(f"pull_off_radius_{_control(control)}", 0.0)

    def pull_off_approach(self, control: str = "force") -> float:
        """Δ̄ at pull-off."""
        return self._eval(f"pull_off_approach_{_control(control)}", 0.0)

    @staticmethod
    def scales(radius: float, modulus: float, work_of_adhesion: float,
               stress: float) -> dict:
        """The units of a sphere of ``radius`` R, ``modulus`` E*, ``work_of_adhesion`` Δγ
        and Dugdale ``stress`` σ₀: ``radius`` (πΔγR²/K)^{1/3} (multiplies Ā), ``force``
        πΔγR (P̄), ``approach`` (π²Δγ²R/K²)^{1/3} (Δ̄) and its ``maugis_parameter`` λ."""
        params = [float(radius), float(modulus), float(work_of_adhesion), float(stress)]
        zero = _np.zeros(())
        value = {name: float(_core.reference("maugis_scales", params, name, [], zero))
                 for name in ("radius", "force", "approach", "lambda")}
        value["maugis_parameter"] = value.pop("lambda")
        return value


class JohnsonSinusoid(_Model):
    """Johnson's adhesive sinusoid (Johnson, Int. J. Solids Struct. 32, 423, 1995): a rigid
    periodic sinusoid ``amplitude · (1 − cos 2πx/λ)`` of ``wavelength`` λ on a half-space
    of ``modulus`` E* with ``work_of_adhesion`` w of vanishing range, as the library's
    ``asperity::reference::JohnsonSinusoid`` (the closed form the adhesive BEM is checked
    against, docs/adhesion.md). At contact half-width a (ψ = πa/λ) the mean pressure is
    ``p̄ = p*[sin²ψ − α√(tan ψ)]``, ``p* = πE*Δ/λ``, ``α = √(2wλ/(π²E*Δ²))``.

    Examples
    --------
    >>> from asperity.reference import JohnsonSinusoid
    >>> j = JohnsonSinusoid(wavelength=1.0, amplitude=0.01, modulus=1.0,
    ...                     work_of_adhesion=1.2337e-4)
    >>> round(j.alpha(), 3)
    0.5
    >>> round(j.pull_off_pressure() / j.full_contact_pressure(), 3)   # force control
    -0.192
    """

    _name, _probe = "johnson_sinusoid", "alpha"
    _params = ("wavelength", "amplitude", "modulus", "work_of_adhesion")

    def full_contact_pressure(self) -> float:
        """Westergaard's ``p* = πE*Δ/λ``."""
        return self._eval("full_contact_pressure", 0.0)

    def alpha(self) -> float:
        """Johnson's parameter ``α = √(2wλ/(π²E*Δ²))``."""
        return self._eval("alpha", 0.0)

    def mean_pressure(self, half_width: Any) -> Any:
        """``p̄`` at contact half-width ``a`` (0 ≤ a < λ/2)."""
        return self._eval("mean_pressure", half_width)

    def approach(self, half_width: Any) -> Any:
        """The approach at ``a``: Westergaard's ``Δr(1 − ln r)``, ``r = sin²ψ``, plus the
        edge punches' ``(2λp̄ₚ/πE*) ln(1/sin ψ)`` (displacements of zero mean)."""
        return self._eval("approach", half_width)

    def stable_branch(self) -> Any:
        """The half-widths ``(least, greatest)`` of the stable branch's least and greatest
        mean pressure, or None when no partial contact is stable (α ≥ 1.065)."""
        least = self._eval("stable_branch_least", 0.0)
        return None if _np.isnan(least) else (least, self._eval("stable_branch_greatest", 0.0))

    def pull_off_half_width(self, control: str = "force") -> float:
        """The half-width at pull-off (NaN when no partial contact is stable)."""
        return self._eval(f"pull_off_half_width_{_control(control)}", 0.0)

    def pull_off_pressure(self, control: str = "force") -> float:
        """The mean pressure at pull-off: the stable branch's least (``"force"``) or the
        one at the least approach (``"displacement"``); NaN when none is stable."""
        return self._eval(f"pull_off_pressure_{_control(control)}", 0.0)

    @staticmethod
    def alpha_stable() -> float:
        """α above which no partial contact is stable, ``4(3/8)^{3/4}(5/8)^{5/4} ≈ 1.065``."""
        return float(_core.reference("johnson_sinusoid", [1.0, 1.0, 1.0, 1.0], "alpha_stable",
                                     [], _np.asarray(0.0)))

    @staticmethod
    def alpha_snap() -> float:
        """α above which the surfaces pull themselves into full contact under no load,
        ``(3/4)^{3/4}/√2 ≈ 0.570``."""
        return float(_core.reference("johnson_sinusoid", [1.0, 1.0, 1.0, 1.0], "alpha_snap",
                                     [], _np.asarray(0.0)))
