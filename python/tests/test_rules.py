"""One set of rules and words: every invalid request below is given to the CLI (the real
binary) and to Python, and both refuse it in the same words, the CLI naming flags
(`--tol`) where Python names keywords (`tolerance`).

The rules live once, in the front-end layer (crates/asperity-app); each row is one rule of
one command, with a fragment of the expected words so that a row cannot pass by some other
refusal."""

import math

import numpy as np
import pytest

import asperity

from conftest import cli_error

# Each flag of the table and the keyword that Python names it by.
KEYWORDS = {
    "--forces": "forces",
    "--pressures": "pressures",
    "--indentations": "indentations",
    "--nloads": "nloads",
    "--pmin": "pmin",
    "--pmax": "pmax",
    "--modulus": "modulus",
    "--young": "young",
    "--poisson": "poisson",
    "--boundary": "boundary",
    "--solver": "solver",
    "--tol": "tolerance",
    "--max-iter": "max_iterations",
    "--n": "n",
    "--hurst": "hurst",
    "--rolloff": "rolloff",
    "--cutoff": "cutoff",
    "--rms-height": "rms_height",
    "--rms-slope": "rms_slope",
    "--size": "size",
    "--seed": "seed",
    "--line": "line",
    "--profile": "profile",
    "--radial": "radial",
    "--radial-step": "radial_step",
    "--radius": "radius",
    "--slope": "slope",
    "--dx": "dx",
    "--spring": "spring",
    "--asperity-radius": "asperity_radius",
    "--dmin": "dmin",
    "--dmax": "dmax",
    "--breakpoints": "breakpoints",
    "--work-of-adhesion": "work_of_adhesion",
    "--min-contacts": "min_contacts",
    "--hardness": "hardness",
    "--fit-from": "fit_from",
    "--fit-to": "fit_to",
    "--detrend": "detrend",
    "--fill": "fill",
    "--tangential-force": "tangential_force",
    "--resistivity": "resistivity",
    "--thermal-conductivity": "thermal_conductivity",
    "--tangential": "tangential",
    "tangential-force": "tangential_force",
    "--friction": "friction",
    "--cycle-points": "cycle_points",
    "--gamma": "gamma",
    "--kappa": "kappa",
    "--persson": "persson",
    "--samples": "samples",
    "--m": "m",
    "--levels": "levels",
    "--method": "method",
}


def in_keywords(words: str) -> str:
    """The CLI's words with each flag replaced by its keyword (longest flags first)."""
    for flag in sorted(KEYWORDS, key=len, reverse=True):
        words = words.replace(flag, KEYWORDS[flag])
    return words


NAN, INF = math.nan, math.inf

# asperity bem: (flags, Solver keywords, sweep keywords, expected words in keywords).
BEM = [
    (["--forces", "-1"], {}, dict(forces=[-1]), "forces: -1 is not allowed (values must be finite and > 0)"),
    (["--forces", "nan"], {}, dict(forces=[NAN]), "forces: NaN is not allowed"),
    (["--pressures", "0"], {}, dict(pressures=[0]), "pressures: 0 is not allowed"),
    (["--pressures", "0.01,inf"], {}, dict(pressures=[0.01, INF]), "pressures: inf is not allowed"),
    (["--indentations", "-0.5"], {}, dict(indentations=[-0.5]), "(values must be finite and >= 0)"),
    ([], {}, {}, "give one of forces, pressures, indentations or nloads with pmin and pmax"),
    (["--forces", "1", "--pressures", "1"], {}, dict(forces=[1], pressures=[1]), "give one of"),
    (["--nloads", "0", "--pmin", "1e-3", "--pmax", "1e-2"], {}, dict(nloads=0, pmin=1e-3, pmax=1e-2),
     "nloads must be at least 1, got 0"),
    (["--nloads", "3", "--pmin", "1e-3"], {}, dict(nloads=3, pmin=1e-3), "nloads needs pmin and pmax"),
    (["--nloads", "3", "--pmin", "-1", "--pmax", "1"], {}, dict(nloads=3, pmin=-1, pmax=1),
     "pmin: -1 is not allowed"),
    (["--nloads", "3", "--pmin", "0.1", "--pmax", "0.01"], {}, dict(nloads=3, pmin=0.1, pmax=0.01),
     "pmax (0.01) must not be smaller than pmin (0.1)"),
    (["--nloads", "3", "--pmin", "1e-3", "--pmax", "nan"], {}, dict(nloads=3, pmin=1e-3, pmax=NAN),
     "pmax: NaN is not allowed"),
    (["--pressures", "0.01", "--tol", "0"], dict(tolerance=0), None,
     "tolerance must be positive and at most 1e-2 (a relative residual), got 0"),
    (["--pressures", "0.01", "--tol", "0.5"], dict(tolerance=0.5), None, "at most 1e-2"),
    (["--pressures", "0.01", "--tol", "10"], dict(tolerance=10), None, "got 10"),
    (["--pressures", "0.01", "--tol=-1e-6"], dict(tolerance=-1e-6), None, "got -1e-6"),
    (["--pressures", "0.01", "--tol", "nan"], dict(tolerance=NAN), None, "tolerance must be positive"),
    (["--pressures", "0.01", "--max-iter", "0"], dict(max_iterations=0), None,
     "max_iterations must be at least 1, got 0"),
    # A negative count: refused in the same words by both (asperity_app::refusal::count;
    # before, clap's "invalid digit" in the CLI and Python's own words).
    (["--pressures", "0.01", "--max-iter", "-1"], dict(max_iterations=-1), None,
     "max_iterations must be at least 1, got -1"),
    (["--nloads", "-3", "--pmin", "1e-3", "--pmax", "1e-2"], {}, dict(nloads=-3, pmin=1e-3, pmax=1e-2),
     "nloads must be at least 1, got -3"),
    (["--pressures", "0.01", "--solver", "cg"], dict(solver="cg"), None,
     'solver must be "bccg" (the default) or "pk" (Polonsky–Keer), got "cg"'),
    (["--pressures", "0.01", "--boundary", "open"], dict(boundary="open"), None,
     'boundary must be "free" (the default) or "periodic", got "open"'),
    (["--pressures", "0.01", "--modulus", "0"], dict(modulus=0), None,
     "modulus must be positive and finite, got 0"),
    (["--pressures", "0.01", "--modulus", "-1"], dict(modulus=-1), None, "got -1"),
    (["--pressures", "0.01", "--modulus", "inf"], dict(modulus=INF), None, "got infinity"),
    (["--pressures", "0.01", "--modulus", "nan"], dict(modulus=NAN), None, "got NaN"),
    (["--pressures", "0.01", "--poisson", "0.7"], {}, dict(pressures=[0.01], poisson=0.7),
     "poisson must be in [0, 0.5] (Poisson's ratio), got 0.7"),
    (["--pressures", "0.01", "--poisson=-0.1"], {}, dict(pressures=[0.01], poisson=-0.1), "got -0.1"),
    (["--pressures", "0.01", "--poisson", "0.3", "--tangential", "z"], {},
     dict(pressures=[0.01], poisson=0.3, tangential="z"), 'tangential must be x, y or both, got "z"'),
    (["--pressures", "0.01", "--tangential", "x"], {}, dict(pressures=[0.01], tangential="x"),
     "tangential needs poisson ν (of Cerruti's kernel)"),
    (["--pressures", "0.01", "--resistivity", "1"], {}, dict(pressures=[0.01], resistivity=[1]),
     "invalid resistivity: give two values, body 1 and body 2, got 1"),
    (["--pressures", "0.01", "--thermal-conductivity", "1,nan"], {},
     dict(pressures=[0.01], thermal_conductivity=[1, NAN]),
     "invalid thermal_conductivity: each body's thermal conductivity must be positive and "
     "finite, got NaN"),
    # The hardness (Solver(hardness=)): positive and finite; no load at or above it, the
    # mean pressures and (over the 1×1 nominal area) the forces, before any solve.
    (["--pressures", "0.01", "--hardness", "0"], dict(hardness=0), None,
     "hardness must be positive and finite, got 0"),
    (["--pressures", "0.01", "--hardness=-1"], dict(hardness=-1), None, "got -1"),
    (["--pressures", "0.01", "--hardness", "nan"], dict(hardness=NAN), None, "got NaN"),
    (["--pressures", "0.01", "--hardness", "inf"], dict(hardness=INF), None, "got infinity"),
    (["--pressures", "0.01,0.3", "--hardness", "0.3"], dict(hardness=0.3),
     dict(pressures=[0.01, 0.3]),
     "a mean pressure of 0.3 is at or above the hardness 0.3: more than a fully plastic "
     "contact can carry (lower it or raise hardness)"),
    (["--nloads", "3", "--pmin", "0.1", "--pmax", "0.5", "--hardness", "0.4"],
     dict(hardness=0.4), dict(nloads=3, pmin=0.1, pmax=0.5), "a mean pressure of 0.5 is"),
    (["--forces", "0.01,0.5", "--hardness", "0.3"], dict(hardness=0.3),
     dict(forces=[0.01, 0.5]),
     "a force of 0.5 (a mean pressure of 0.5) is at or above the hardness 0.3"),
    (["--pressures", "0.01", "--hardness", "0.3", "--solver", "pk", "--poisson", "0.7"],
     dict(hardness=0.3, solver="pk"), dict(pressures=[0.01], poisson=0.7),
     "poisson must be in [0, 0.5]"),
    # The side lengths of the surface argument (asperity_app::argument::sizes: one or two,
    # positive and finite; before, Python's own words and the CLI's "invalid --size").
    (["--pressures", "0.01", "--size", "-1"], dict(size=-1), None,
     "size must be positive and finite, got -1"),
    (["--pressures", "0.01", "--size", "1,0"], dict(size=(1, 0)), None, "got 0"),
    (["--pressures", "0.01", "--size", "nan"], dict(size=NAN), None, "got NaN"),
    (["--pressures", "0.01", "--size", "1,2,3"], dict(size=(1, 2, 3)), None,
     "size takes one value (x) or two (x and y), got 3"),
    # Persson's theory beside the sweep (asperity_app::persson::SweepPersson::from_options).
    (["--pressures", "0.01", "--gamma", "0.4"], {}, dict(pressures=[0.01], gamma=0.4),
     "gamma goes with persson"),
    (["--pressures", "0.01", "--kappa", "2"], {}, dict(pressures=[0.01], kappa=2),
     "kappa goes with persson"),
]

# asperity contact: (flags, keywords, expected words in keywords).
CONTACT = [
    (["--pressures", "1e5"], dict(pressures=[1e5]), "give either modulus E* or young E with poisson ν"),
    (["--young", "1e9", "--pressures", "1e5"], dict(young=1e9, pressures=[1e5]), "give either"),
    (["--poisson", "0.3", "--pressures", "1e5"], dict(poisson=0.3, pressures=[1e5]), "give either"),
    (["--modulus", "1e9", "--young", "1e9", "--poisson", "0.3", "--pressures", "1e5"],
     dict(modulus=1e9, young=1e9, poisson=0.3, pressures=[1e5]), "give either"),
    (["--young", "1e9", "--poisson", "0.6", "--pressures", "1e5"],
     dict(young=1e9, poisson=0.6, pressures=[1e5]), "poisson must be in [0, 0.5] (Poisson's ratio), got 0.6"),
    (["--young", "1e9", "--poisson", "-0.1", "--pressures", "1e5"],
     dict(young=1e9, poisson=-0.1, pressures=[1e5]), "got -0.1"),
    (["--young", "1e9", "--poisson", "nan", "--pressures", "1e5"],
     dict(young=1e9, poisson=NAN, pressures=[1e5]), "poisson must be in"),
    (["--young", "1e9", "--poisson", "0.3", "--pressures", "1e5", "--tangential=X"],
     dict(young=1e9, poisson=0.3, pressures=[1e5], tangential="X"),
     'tangential must be x, y or both, got "X"'),
    (["--young", "-1", "--poisson", "0.3", "--pressures", "1e5"],
     dict(young=-1, poisson=0.3, pressures=[1e5]), "young must be positive and finite, got -1"),
    # Two bodies: one E and one ν each, no E* beside them; three values are none of those.
    (["--young", "1e9,2e9", "--poisson", "0.3", "--pressures", "1e5"],
     dict(young=[1e9, 2e9], poisson=0.3, pressures=[1e5]),
     "give each body's young E and poisson ν: two values each (E₁,E₂ and ν₁,ν₂)"),
    (["--modulus", "1e9", "--young", "1e9,2e9", "--poisson", "0.3,0.3", "--pressures", "1e5"],
     dict(modulus=1e9, young=[1e9, 2e9], poisson=[0.3, 0.3], pressures=[1e5]),
     "two bodies take young E₁,E₂ with poisson ν₁,ν₂ and no modulus"),
    (["--young", "1e9,2e9,3e9", "--poisson", "0.3", "--pressures", "1e5"],
     dict(young=[1e9, 2e9, 3e9], poisson=0.3, pressures=[1e5]),
     "young takes one value, or two (one per body), got 3"),
    (["--young", "1e9,2e9", "--poisson", "0.3,0.7", "--pressures", "1e5"],
     dict(young=[1e9, 2e9], poisson=[0.3, 0.7], pressures=[1e5]),
     "poisson must be in [0, 0.5] (Poisson's ratio), got 0.7"),
    (["--young", "1e9,2e9", "--poisson", "0.3,0.2", "--pressures", "1e5", "--tangential"],
     dict(young=[1e9, 2e9], poisson=[0.3, 0.2], pressures=[1e5], tangential=True),
     "tangential needs one Poisson's ratio (Cerruti's kernel): the two bodies' poisson differ "
     "(0.3, 0.2)"),
    (["--modulus", "0", "--pressures", "1e5"], dict(modulus=0, pressures=[1e5]),
     "modulus must be positive and finite, got 0"),
    (["--modulus", "1e9", "--pressures", "-1"], dict(modulus=1e9, pressures=[-1]),
     "pressures: -1 is not allowed"),
    (["--modulus", "1e9"], dict(modulus=1e9, pressures=[]), "pressures: give at least one value"),
    # The reliability item: contact's tolerance had no upper bound (Python's 10 was taken).
    (["--modulus", "1e9", "--pressures", "1e5", "--tol", "10"],
     dict(modulus=1e9, pressures=[1e5], tolerance=10), "tolerance must be positive and at most 1e-2"),
    (["--modulus", "1e9", "--pressures", "1e5", "--tol", "0"],
     dict(modulus=1e9, pressures=[1e5], tolerance=0), "got 0"),
    (["--modulus", "1e9", "--pressures", "1e5", "--boundary", "open"],
     dict(modulus=1e9, pressures=[1e5], boundary="open"), 'boundary must be "free"'),
    (["--modulus", "1e9", "--pressures", "1e5", "--hardness", "-1"],
     dict(modulus=1e9, pressures=[1e5], hardness=-1), "hardness must be positive and finite, got -1"),
    (["--modulus", "1e9", "--pressures", "1e5", "--hardness", "1e5"],
     dict(modulus=1e9, pressures=[1e5], hardness=1e5),
     "a mean pressure of 100000 Pa is at or above the hardness 100000 Pa"),
    (["--modulus", "1e9", "--pressures", "1e5", "--resistivity", "1e-8"],
     dict(modulus=1e9, pressures=[1e5], resistivity=[1e-8]),
     "invalid resistivity: give two values, body 1 and body 2, got 1"),
    (["--modulus", "1e9", "--pressures", "1e5", "--resistivity", "1e-8,0"],
     dict(modulus=1e9, pressures=[1e5], resistivity=[1e-8, 0]),
     "invalid resistivity: each body's resistivity must be positive and finite, got 0"),
    (["--modulus", "1e9", "--pressures", "1e5", "--thermal-conductivity", "inf,1"],
     dict(modulus=1e9, pressures=[1e5], thermal_conductivity=[INF, 1]),
     "invalid thermal_conductivity: each body's thermal conductivity must be positive and "
     "finite, got infinity"),
    (["--modulus", "1e9", "--pressures", "1e5", "--thermal-conductivity", "1,-5"],
     dict(modulus=1e9, pressures=[1e5], thermal_conductivity=[1, -5]), "got -5"),
    (["--modulus", "1e9", "--pressures", "1e5", "--tangential"],
     dict(modulus=1e9, pressures=[1e5], tangential=True),
     "tangential needs poisson ν (of Cerruti's kernel)"),
    (["--modulus", "1e9", "--poisson", "0.6", "--pressures", "1e5", "--tangential"],
     dict(modulus=1e9, poisson=0.6, pressures=[1e5], tangential=True),
     "poisson must be in [0, 0.5] (Poisson's ratio), got 0.6"),
]


# asperity surface / line: (command, flags, keywords, expected words in keywords).
SURFACE = [
    ("surface", ["--seed", "1.5"], dict(seed=1.5),
     "seed must be a whole number from 0 to 18446744073709551615, got 1.5"),
    ("surface", ["--seed", "-1"], dict(seed=-1), "got -1"),
    ("line", ["--seed", "True"], dict(seed=True), "got True"),
    ("surface", ["--rolloff", "2", "--cutoff", "2"], dict(rolloff=2, cutoff=2),
     "give at most one of rolloff and cutoff (a roll-off keeps the power below q0 flat"),
    ("line", ["--rms-height", "1", "--rms-slope", "1"], dict(rms_height=1, rms_slope=1),
     "give at most one of rms_height and rms_slope"),
    # A negative count (asperity_app::surface::grid; before, clap's "invalid digit" and
    # Python's OverflowError).
    ("surface", ["--m", "-3"], dict(m=-3), "m must be at least 1, got -3"),
    # A grid below 2x2 names the count that is wrong (the library's rule; before, n for both).
    ("surface", ["--m", "0"], dict(m=0), "invalid m: grid must be at least 2x2, got 0x16"),
    ("surface", ["--m", "1"], dict(m=1), "invalid m: grid must be at least 2x2, got 1x16"),
    ("surface", ["--rms-height", "1e-320"], dict(rms_height=1e-320),
     "the generated heights are not representable (rms height 1e-320): rms_height or "
     "rms_slope with size 1 is beyond the range of float64"),
]


# asperity mdr: (flags, keywords, expected words in keywords); "LINE" is a line's file for the
# CLI and its heights for Python.
HERTZ = (["--profile", "hertz", "--radius", "1", "--n", "11", "--dx", "0.1"],
         dict(profile="hertz", radius=1, n=11, dx=0.1))
MDR = [
    ([], {}, "give an indenter: line, profile hertz|cone|punch|power or radial"),
    (["--line", "LINE", "--profile", "hertz"], dict(line="LINE", profile="hertz"),
     "give one indenter: line, profile or radial"),
    (["--line", "LINE", "--n", "5"], dict(line="LINE", n=5),
     "n and dx are for profile and radial indenters"),
    (["--radial", "LINE", "--n", "5", "--dx", "1e-3"], dict(radial="LINE", n=5, dx=1e-3),
     "radial needs radial_step"),
    (["--profile", "sphere", "--radius", "1", "--n", "11", "--dx", "0.1"],
     dict(profile="sphere", radius=1, n=11, dx=0.1),
     'profile must be hertz, cone, punch or power, got "sphere"'),
    (["--profile", "hertz", "--n", "11", "--dx", "0.1"], dict(profile="hertz", n=11, dx=0.1),
     "profile hertz needs radius"),
    (["--profile", "cone", "--n", "11", "--dx", "0.1"], dict(profile="cone", n=11, dx=0.1),
     "profile cone needs slope"),
    (["--profile", "hertz", "--radius", "1", "--dx", "0.1"], dict(profile="hertz", radius=1, dx=0.1),
     "profile needs n (number of springs)"),
    (["--profile", "hertz", "--radius", "1", "--n", "11", "--dx", "0"],
     dict(profile="hertz", radius=1, n=11, dx=0),
     "invalid dx: the spring spacing Δx must be positive and finite, got 0"),
    (HERTZ[0] + ["--spring", "hertz2"], dict(HERTZ[1], spring="hertz2"),
     'spring must be linear, hertz or fractal, got "hertz2"'),
    (["--line", "LINE", "--spring", "hertz"], dict(line="LINE", spring="hertz"),
     "the hertz spring law (15.2) needs asperity_radius"),
    (["--line", "LINE", "--spring", "fractal"], dict(line="LINE", spring="fractal"),
     "the fractal spring law (15.7) needs hurst"),
    (HERTZ[0] + ["--spring", "fractal", "--hurst", "0.5"], dict(HERTZ[1], spring="fractal", hurst=0.5),
     "the fractal spring law (15.7) on a profile needs rms_height"),
    (["--line", "LINE", "--breakpoints", "--nloads", "3"], dict(line="LINE", breakpoints=True, nloads=3),
     "breakpoints gives the exact curve: drop indentations and nloads"),
    (["--line", "LINE", "--nloads", "-1"], dict(line="LINE", nloads=-1),
     "nloads must be at least 1, got -1"),
    (["--profile", "hertz", "--radius", "1", "--n", "-11", "--dx", "0.1"],
     dict(profile="hertz", radius=1, n=-11, dx=0.1), "n must be at least 1, got -11"),
    (["--line", "LINE", "--indentations", "1", "--nloads", "3"],
     dict(line="LINE", indentations=[1], nloads=3), "give at most one of indentations and nloads"),
    (["--line", "LINE", "--indentations", "-1"], dict(line="LINE", indentations=[-1]),
     "invalid indentations: each must be finite and >= 0, got -1"),
    (HERTZ[0] + ["--breakpoints"], dict(HERTZ[1], breakpoints=True),
     "breakpoints needs line with linear springs"),
    (["--profile", "punch", "--radius", "0.1", "--n", "401", "--dx", "1e-3"],
     dict(profile="punch", radius=0.1, n=401, dx=1e-3), "give dmax, or indentations"),
    (HERTZ[0] + ["--dmin", "-1"], dict(HERTZ[1], dmin=-1), "dmin/dmax/nloads: "),
    (HERTZ[0] + ["--work-of-adhesion", "0"], dict(HERTZ[1], work_of_adhesion=0),
     "invalid work_of_adhesion: the work of adhesion Δγ must be positive and finite, got 0"),
    (HERTZ[0] + ["--work-of-adhesion", "inf"], dict(HERTZ[1], work_of_adhesion=float("inf")),
     "invalid work_of_adhesion: the work of adhesion Δγ must be positive and finite, got infinity"),
    (HERTZ[0] + ["--work-of-adhesion", "-1e-3"], dict(HERTZ[1], work_of_adhesion=-1e-3),
     "invalid work_of_adhesion: the work of adhesion Δγ must be positive and finite, got -0.001"),
    (HERTZ[0] + ["--work-of-adhesion", "1e-3", "--spring", "hertz"],
     dict(HERTZ[1], work_of_adhesion=1e-3, spring="hertz"),
     "work_of_adhesion needs linear springs"),
]


# asperity stats (on the 32 × 32 surface: Nyquist at q·L/2π = 16): (flags, keywords,
# expected words in keywords).
STATS = [
    (["--fit-from", "-1"], dict(fit_from=-1),
     "invalid fit_from: must be a positive number of wavelengths per side, got -1"),
    (["--fit-to", "0"], dict(fit_to=0), "invalid fit_to: must be a positive number"),
    (["--fit-from", "nan"], dict(fit_from=NAN), "got NaN"),
    (["--fit-from", "8", "--fit-to", "4"], dict(fit_from=8, fit_to=4),
     "invalid PSD fit range: fit_from 8 must be below fit_to 4"),
    (["--fit-from", "20"], dict(fit_from=20),
     "invalid fit_from 20: the PSD fit range would be empty, its upper end is 16 (Nyquist); "
     "give a smaller fit_from"),
    (["--fit-to", "1.5"], dict(fit_to=1.5),
     "invalid fit_to 1.5: the PSD fit range would be empty, its lower end is 2 (the default "
     "lower end); give a larger fit_to or a smaller fit_from"),
    (["--size", "-2"], dict(size=-2), "size must be positive and finite, got -2"),
    (["--size", "inf"], dict(size=INF), "size must be positive and finite, got infinity"),
]

# A measured file's cleaning (every command that reads one; Python's read_topography):
# (flags, keywords, expected words in keywords).
MEASURED = [
    (["--detrend", "tilt"], dict(detrend="tilt"),
     'detrend must be one of none, mean, plane, poly2, poly3, lines, line-means, got "tilt"'),
    (["--fill", "zero"], dict(fill="zero"),
     'fill must be harmonic (Laplace inpainting) or refuse, got "zero"'),
    (["--size", "0"], dict(size=0), "size must be positive and finite, got 0"),
    # Numbers as every refusal writes them (asperity_app::refusal::number): -1e-6, not
    # -0.000001.
    (["--size", "1e-6,-1e-6"], dict(size=(1e-6, -1e-6)), "got -1e-6"),
    (["--size", "1,2,3"], dict(size=(1, 2, 3)), "size takes one value (x) or two (x and y)"),
]

# asperity persson: (flags, keywords, expected words in keywords). Its loads follow bem's
# rules for --pressures and --nloads, word for word.
PERSSON = [
    (["--pressures", "0"], dict(pressures=[0]),
     "pressures: 0 is not allowed (values must be finite and > 0)"),
    (["--pressures", "0.01,inf"], dict(pressures=[0.01, INF]), "pressures: inf is not allowed"),
    ([], {}, "give pressures or nloads with pmin and pmax, not both"),
    (["--pressures", "0.1", "--nloads", "3", "--pmin", "1e-3", "--pmax", "0.1"],
     dict(pressures=[0.1], nloads=3, pmin=1e-3, pmax=0.1), "give pressures or nloads"),
    (["--pressures", "0.1", "--pmin", "1e-3"], dict(pressures=[0.1], pmin=1e-3), ", not both"),
    (["--pmin", "1e-3", "--pmax", "0.1"], dict(pmin=1e-3, pmax=0.1), "give pressures or"),
    (["--nloads", "3", "--pmax", "0.1"], dict(nloads=3, pmax=0.1), "nloads needs pmin and pmax"),
    (["--nloads", "0", "--pmin", "1e-3", "--pmax", "1e-2"], dict(nloads=0, pmin=1e-3, pmax=1e-2),
     "nloads must be at least 1, got 0"),
    (["--nloads", "-2", "--pmin", "1e-3", "--pmax", "1e-2"], dict(nloads=-2, pmin=1e-3, pmax=1e-2),
     "nloads must be at least 1, got -2"),
    (["--nloads", "3", "--pmin", "0.1", "--pmax", "0.01"], dict(nloads=3, pmin=0.1, pmax=0.01),
     "pmax (0.01) must not be smaller than pmin (0.1)"),
    (["--nloads", "3", "--pmin", "0", "--pmax", "0.01"], dict(nloads=3, pmin=0, pmax=0.01),
     "pmin: 0 is not allowed"),
    (["--pressures", "0.1", "--gamma", "0"], dict(pressures=[0.1], gamma=0),
     "invalid gamma: Persson's γ must lie in (0, 1], got 0"),
    (["--pressures", "0.1", "--kappa", "-1"], dict(pressures=[0.1], kappa=-1),
     "invalid kappa: κ must be positive and finite, got -1"),
    (["--pressures", "0.1", "--modulus", "nan"], dict(pressures=[0.1], modulus=NAN),
     "invalid modulus: E* must be positive and finite, got NaN"),
]

# asperity study alpha|curve (Python: study_alpha, study_curve): (kind, keywords changed
# from a valid MDR study of one N and one H, expected words in keywords); the flags are the
# keywords' (`min_contacts` → `--min-contacts`, a list comma-separated). The study's request
# is the front-end layer's (asperity_app::study::request): the method by name and every
# count read there, a negative one refused as nloads is.
STUDY = [
    ("alpha", dict(n=-32), "n must be at least 1, got -32"),
    ("alpha", dict(n=[64, -32]), "n must be at least 1, got -32"),
    ("curve", dict(n=-32), "n must be at least 1, got -32"),
    ("alpha", dict(samples=-1), "samples must be at least 1, got -1"),
    ("curve", dict(samples=-4), "samples must be at least 1, got -4"),
    ("alpha", dict(levels=-3), "levels must be at least 1, got -3"),
    ("alpha", dict(min_contacts=-1), "min_contacts must be at least 1, got -1"),
    ("curve", dict(seed=-1), "seed must be a whole number from 0 to 18446744073709551615, got -1"),
    ("alpha", dict(method="fem"), 'method must be mdr or bem, got "fem"'),
    ("curve", dict(method="MDR"), 'method must be mdr or bem, got "MDR"'),
    ("curve", dict(method="bem", poisson=0.3, tangential="xy"),
     'tangential must be x, y or both, got "xy"'),
    ("curve", dict(method="bem", tangential="x"), "tangential needs poisson ν (of Cerruti's kernel)"),
]

ALL = BEM + CONTACT + SURFACE + MDR + STATS + MEASURED + PERSSON + STUDY
# asperity mdr --tangential-force (Python: mdr_slip): (flags, keywords, expected words in
# keywords), on a sphere at d = 1 (μF = 2/3 with μ = 0.5).
SPHERE = (["--profile", "hertz", "--radius", "1", "--n", "401", "--dx", "0.01", "--indentations", "1"],
          dict(profile="hertz", radius=1, n=401, dx=0.01, indentations=[1]))
SLIP = [
    (["--tangential-force", "0.1", "--friction", "0.5", "--poisson", "0.6"],
     dict(tangential_force=0.1, friction=0.5, poisson=0.6),
     "invalid poisson: Poisson's ratio ν must be in [0, 0.5], got 0.6"),
    (["--tangential-force", "0.1", "--friction", "0.5", "--poisson", "-0.1"],
     dict(tangential_force=0.1, friction=0.5, poisson=-0.1), "got -0.1"),
    (["--tangential-force", "0.1"], dict(tangential_force=0.1), "tangential_force needs friction"),
    (["--tangential-force", "0.1", "--friction", "0"], dict(tangential_force=0.1, friction=0),
     "invalid friction: the friction coefficient μ must be positive and finite, got 0"),
    (["--tangential-force", "0.1", "--friction", "inf"], dict(tangential_force=0.1, friction=INF),
     "invalid friction: the friction coefficient μ must be positive and finite, got infinity"),
    (["--tangential-force", "-1", "--friction", "0.5"], dict(tangential_force=-1, friction=0.5),
     "invalid tangential_force: the tangential force Q* must be positive and finite, got -1"),
    (["--tangential-force", "0.7", "--friction", "0.5"], dict(tangential_force=0.7, friction=0.5),
     "invalid tangential_force: the tangential force Q must be finite with |Q| <= μF = 0.6667 "
     "(beyond it the contact slides as a whole), got 0.7"),
    (["--tangential-force", "0.1", "--friction", "0.5", "--work-of-adhesion", "1e-3"],
     dict(tangential_force=0.1, friction=0.5, work_of_adhesion=1e-3),
     "tangential_force is for non-adhesive contact: drop work_of_adhesion"),
    (["--tangential-force", "0.1", "--friction", "0.5", "--cycle-points", "1"],
     dict(tangential_force=0.1, friction=0.5, cycle_points=1),
     "invalid cycle_points: a branch needs at least 2 points, got 1"),
    (["--tangential-force", "0.1", "--friction", "0.5", "--cycle-points", "-3"],
     dict(tangential_force=0.1, friction=0.5, cycle_points=-3),
     "invalid cycle_points: a branch needs at least 2 points, got -3"),
]


@pytest.mark.parametrize("flags,kwargs,words", SLIP)
def test_mdr_slip_refuses_alike(cli, flags, kwargs, words):
    theirs = in_keywords(cli_error(cli("mdr", *SPHERE[0], *flags, ok=False)))
    ours = python_words(lambda: asperity.mdr_slip(**SPHERE[1], **kwargs))
    assert ours == theirs
    assert words in ours


def test_mdr_slip_needs_one_indentation_alike(cli):
    flags = ["--profile", "hertz", "--radius", "1", "--n", "401", "--dx", "0.01",
             "--indentations", "0.5,1", "--tangential-force", "0.1", "--friction", "0.5"]
    theirs = in_keywords(cli_error(cli("mdr", *flags, ok=False)))
    ours = python_words(lambda: asperity.mdr_slip(
        profile="hertz", radius=1, n=401, dx=0.01, indentations=[0.5, 1], tangential_force=0.1,
        friction=0.5))
    assert ours == theirs == "tangential_force needs exactly one indentation: indentations d"


def test_mdr_slip_equals_the_cli(cli, tmp_path):
    """`asperity.mdr_slip` gives the CLI's cycle bit for bit, and Cattaneo–Mindlin's stick
    radius at the top of the loading branch (a/Δx = 200: within 1e-2)."""
    cli("mdr", *SPHERE[0], "--tangential-force", 1 / 3, "--friction", 0.5, "--cycle-points", 9,
        "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True, dtype=None,
                           encoding="utf-8")
    ours = asperity.mdr_slip(**SPHERE[1], tangential_force=1 / 3, friction=0.5, cycle_points=9)
    assert list(theirs["branch"]) == ours.branch
    for name in ["tangential_displacement", "tangential_force", "stick_springs", "stick_radius"]:
        assert np.array_equal(getattr(ours, name), theirs[name]), name
    assert abs(ours.stick_radius[8] - 0.5 ** (1 / 3)) < 1e-2
    assert ours.summary["stiffness_ratio"] == 2 * 0.7 / 1.7


def test_contact_conductance_is_the_clis_and_barbers(cli, tmp_path):
    """The conductance columns are the CLI's bit for bit, and 2k/(E*(ρ₁+ρ₂)),
    (2k/E*)·κ₁κ₂/(κ₁+κ₂) of the stiffness column."""
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1, seed=3, size=1e-4)
    heights = s.heights * 1e-6
    np.save(tmp_path / "h.npy", heights)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none", "--out", tmp_path / "t.npy")
    cli("contact", tmp_path / "t.npy", "--modulus", 1e11, "--pressures", "1e4,1e5",
        "--resistivity", "1.7e-8,2.8e-8", "--thermal-conductivity", "400,50", "--detrend", "none",
        "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    t = asperity.read_topography(tmp_path / "t.npy")
    ours = asperity.contact(t, modulus=1e11, pressures=[1e4, 1e5],
                            resistivity=[1.7e-8, 2.8e-8], thermal_conductivity=[400, 50])
    for name in ["stiffness_n_per_m", "electrical_conductance_s", "thermal_conductance_w_per_k"]:
        assert np.array_equal(ours[name], theirs[name]), name
    k = ours["stiffness_n_per_m"]
    assert np.allclose(ours["electrical_conductance_s"], 2 * k / (1e11 * 4.5e-8), rtol=1e-14)
    assert np.allclose(ours["thermal_conductance_w_per_k"], 2 * k / 1e11 * 400 * 50 / 450, rtol=1e-14)


def test_the_table_covers_every_rule_of_every_command_moved():
    assert len(ALL) >= 30
    fragments = [row[-1] for row in ALL]
    assert all(fragments)


@pytest.fixture(scope="module")
def heights(tmp_path_factory):
    s = asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1, seed=1)
    path = tmp_path_factory.mktemp("rules") / "s.npy"
    s.save(path)
    return s.heights, path


def python_words(call) -> str:
    with pytest.raises(ValueError) as refused:
        call()
    return str(refused.value)


@pytest.mark.parametrize("flags,solver_kw,sweep_kw,words", BEM)
def test_bem_refuses_alike(cli, heights, flags, solver_kw, sweep_kw, words):
    array, path = heights
    theirs = in_keywords(cli_error(cli("bem", "--surface", path, *flags, ok=False)))

    def call():
        solver = asperity.Solver(array, **solver_kw)
        solver.sweep(**(sweep_kw if sweep_kw is not None else dict(pressures=[0.01])))

    ours = python_words(call)
    assert ours == theirs
    assert words in ours


@pytest.mark.parametrize("flags,kwargs,words", CONTACT)
def test_contact_refuses_alike(cli, heights, flags, kwargs, words):
    array, path = heights
    theirs = in_keywords(cli_error(cli("contact", path, *flags, ok=False)))
    ours = python_words(lambda: asperity.contact(array, 1e-4, **kwargs))
    assert ours == theirs
    assert words in ours


@pytest.mark.parametrize("command,flags,kwargs,words", SURFACE)
def test_surfaces_refuse_alike(cli, tmp_path, command, flags, kwargs, words):
    theirs = cli(command, "--n", 16, "--hurst", 0.5, *flags, "--out", tmp_path / "x.npy", ok=False)
    theirs = in_keywords(cli_error(theirs))
    ours = python_words(lambda: getattr(asperity, command)(16, hurst=0.5, **kwargs))
    assert ours == theirs
    assert words in ours
    assert not (tmp_path / "x.npy").exists()


@pytest.mark.parametrize("flags,kwargs,words", MDR)
def test_mdr_refuses_alike(cli, tmp_path, flags, kwargs, words):
    heights = np.sin(np.arange(64) * 0.3)
    np.save(tmp_path / "l.npy", heights)
    flags = [str(tmp_path / "l.npy") if f == "LINE" else f for f in flags]
    kwargs = {k: heights if v == "LINE" else v for k, v in kwargs.items()}
    theirs = in_keywords(cli_error(cli("mdr", *flags, ok=False)))
    ours = python_words(lambda: asperity.mdr(**kwargs))
    assert ours == theirs
    assert words in ours


@pytest.mark.parametrize("flags,kwargs,words", PERSSON)
def test_persson_refuses_alike(cli, heights, tmp_path, flags, kwargs, words):
    array, path = heights
    out = tmp_path / "p.csv"
    theirs = in_keywords(cli_error(cli("persson", path, *flags, "--out", out, ok=False)))
    ours = python_words(lambda: asperity.persson(array, **kwargs))
    assert ours == theirs
    assert words in ours
    assert not out.exists()


@pytest.mark.parametrize("flags,kwargs,words", STATS)
def test_stats_refuses_alike(cli, heights, flags, kwargs, words):
    array, path = heights
    theirs = in_keywords(cli_error(cli("stats", path, *flags, ok=False)))
    ours = python_words(lambda: asperity.stats(array, **kwargs))
    assert ours == theirs
    assert words in ours
    assert python_words(lambda: asperity.psd(array, **kwargs)) == ours


@pytest.mark.parametrize("command", ["stats", "import", "contact"])
@pytest.mark.parametrize("flags,kwargs,words", MEASURED)
def test_measured_options_are_refused_alike(cli, heights, tmp_path, command, flags, kwargs, words):
    _, path = heights
    extra = {"import": ["--out", tmp_path / "t.npy"], "contact": ["--modulus", "1e9", "--pressures", "1e5"]}
    theirs = in_keywords(cli_error(cli(command, path, *flags, *extra.get(command, []), ok=False)))
    ours = python_words(lambda: asperity.read_topography(path, **kwargs))
    assert ours == theirs
    assert words in ours


@pytest.mark.parametrize("kind,changes,words", STUDY)
def test_studies_refuse_alike(cli, tmp_path, kind, changes, words):
    keywords = dict(dict(method="mdr", n=32, hurst=0.5, samples=2), **changes)
    flags = []
    for name, value in keywords.items():
        text = ",".join(map(str, value)) if isinstance(value, list) else str(value)
        flags += ["--" + name.replace("_", "-"), text]
    theirs = in_keywords(cli_error(cli("study", kind, *flags, "--out", tmp_path / "cli", ok=False)))
    ours = python_words(lambda: getattr(asperity, f"study_{kind}")(**keywords, out=tmp_path / "py"))
    assert ours == theirs
    assert words in ours
    assert not (tmp_path / "cli").exists() and not (tmp_path / "py").exists()


@pytest.mark.parametrize("command,n", [("surface", -16), ("line", -8)])
def test_a_negative_grid_size_is_refused_alike(cli, tmp_path, command, n):
    theirs = cli(command, "--n", n, "--hurst", 0.5, "--out", tmp_path / "x.npy", ok=False)
    ours = python_words(lambda: getattr(asperity, command)(n, hurst=0.5))
    assert ours == in_keywords(cli_error(theirs)) == f"n must be at least 1, got {n}"
    assert not (tmp_path / "x.npy").exists()


@pytest.mark.parametrize("method,n,min_contacts", [("mdr", 32, 33), ("bem", 8, 65)])
def test_a_fit_window_above_the_grid_is_refused_alike(cli, tmp_path, method, n, min_contacts):
    theirs = cli("study", "alpha", "--method", method, "--n", n, "--hurst", 0.5, "--samples", 1,
                 "--min-contacts", min_contacts, "--out", tmp_path / "cli", ok=False)
    theirs = in_keywords(cli_error(theirs))
    ours = python_words(lambda: asperity.study_alpha(
        method=method, n=n, hurst=0.5, samples=1, min_contacts=min_contacts, out=tmp_path / "py"))
    assert ours == theirs
    assert f"min_contacts {min_contacts} is above the number of points" in ours
    assert not (tmp_path / "cli").exists() and not (tmp_path / "py").exists()


def test_contact_with_a_hardness_equals_the_cli(cli, tmp_path):
    """`asperity.contact(hardness=)` gives the CLI's `--hardness` table bit for bit, with
    the plastic columns: every pressure at most H, so F ≤ H·A; part of the contact plastic
    (plastic_area_m2 its fraction of the nominal area). Refusals: the CONTACT table."""
    s = asperity.surface(64, hurst=0.8, rolloff=2, rms_slope=1, seed=2, size=1e-4)
    heights = s.heights * 1e-6
    np.save(tmp_path / "h.npy", heights)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none", "--out", tmp_path / "t.npy")
    t = asperity.read_topography(tmp_path / "t.npy", detrend="none")
    # The mildest cap (from above) under which both loads are partly plastic.
    hardness = next(h for h in [3e6, 1e6, 6e5, 4e5, 3e5, 2e5]
                    if asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e4, 1e5],
                                        hardness=h).plastic_fraction.min() > 0)
    cli("contact", tmp_path / "t.npy", "--young", 210e9, "--poisson", 0.3, "--pressures",
        "1e4,1e5", "--hardness", hardness, "--detrend", "none", "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    assert "plastic_fraction" in theirs.dtype.names and "plastic_area_m2" in theirs.dtype.names
    ours = asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e4, 1e5], hardness=hardness)
    for name in theirs.dtype.names:
        assert np.array_equal(ours[name], theirs[name]), name
    assert np.all(ours.force_n <= hardness * ours.contact_area_m2 * (1 + 1e-12))
    assert np.all(ours.plastic_fraction > 0) and np.all(ours.plastic_fraction < ours.area_fraction)
    assert np.allclose(ours.plastic_area_m2, ours.plastic_fraction * 1e-8, rtol=1e-12)
    elastic = asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e4, 1e5])
    # The cap spreads the load: never less area than the elastic contact, more where much
    # of it is plastic.
    assert np.all(ours.contact_area_m2 >= elastic.contact_area_m2)
    assert ours.contact_area_m2[-1] > elastic.contact_area_m2[-1]


def test_contact_equals_the_cli(cli, tmp_path):
    """`asperity.contact` gives the CLI's table bit for bit (the same request and sweep)."""
    s = asperity.surface(64, hurst=0.8, rolloff=2, rms_slope=1, seed=2, size=1e-4)
    heights = s.heights * 1e-6
    np.save(tmp_path / "h.npy", heights)
    cli("import", tmp_path / "h.npy", "--size", "1e-4", "--detrend", "none", "--out", tmp_path / "t.npy")
    cli("contact", tmp_path / "t.npy", "--young", 210e9, "--poisson", 0.3, "--pressures",
        "1e4,1e5", "--detrend", "none", "--out", tmp_path / "c.csv")
    theirs = np.genfromtxt(tmp_path / "c.csv", delimiter=",", names=True)
    t = asperity.read_topography(tmp_path / "t.npy", detrend="none")
    ours = asperity.contact(t, young=210e9, poisson=0.3, pressures=[1e4, 1e5], map=True)
    for name in theirs.dtype.names:
        assert np.array_equal(ours[name], theirs[name]), name
    assert ours.map.dtype == bool and ours.map.sum() > 0
    assert ours.effective_modulus == 210e9 / (1 - 0.3**2)


# Defaults shared by a CLI flag and a Python keyword (written once, in the front-end layer):
# (command, flag, the Python callable, keyword).
SHARED_DEFAULTS = [
    ("bem", "--modulus", "bem_adhesion", "modulus"),
    ("bem", "--boundary", "Solver", "boundary"),
    ("bem", "--tol", "Solver", "tolerance"),
    ("bem", "--max-iter", "Solver", "max_iterations"),
    ("bem", "--solver", "Solver", "solver"),
    ("bem", "--boundary", "bem_adhesion", "boundary"),
    ("contact", "--boundary", "contact", "boundary"),
    ("contact", "--tol", "contact", "tolerance"),
    ("persson", "--modulus", "persson", "modulus"),
    ("persson", "--gamma", "persson", "gamma"),
    ("persson", "--kappa", "persson", "kappa"),
    ("surface", "--size", "surface", "size"),
    ("surface", "--seed", "surface", "seed"),
    ("line", "--size", "line", "size"),
    ("line", "--seed", "line", "seed"),
    ("surface", "--size", "Surface", "size"),
    ("line", "--size", "Line", "size"),
    ("stats", "--window", "stats", "window"),
    ("stats", "--window", "psd", "window"),
    ("stats", "--psd-convention", "psd", "convention"),
]


@pytest.mark.parametrize("command,flag,function,keyword", SHARED_DEFAULTS)
def test_python_defaults_are_the_clis(cli, command, flag, function, keyword):
    import inspect
    import re

    # clap prints a flag's help on its line, or on the lines below it when any help of
    # the command is long: the flag's entry runs to the next flag or blank line.
    help_lines = cli(command, "--help").stdout.splitlines()
    starts = [i for i, l in enumerate(help_lines) if re.match(rf"\s+(-\w, )?{flag} ", l)]
    assert len(starts) == 1, starts
    entry = [help_lines[starts[0]]]
    for line in help_lines[starts[0] + 1:]:
        if not line.strip() or re.match(r"\s{0,8}-", line):
            break
        entry.append(line)
    theirs = re.findall(r"\[default: ([^\]]+)\]", " ".join(entry))[-1]
    ours = inspect.signature(getattr(asperity, function)).parameters[keyword].default
    if isinstance(ours, str):
        assert ours == theirs
    else:
        assert ours == type(ours)(float(theirs)), (ours, theirs)


def test_a_fifo_given_as_the_input_is_refused_alike(cli, tmp_path):
    """A FIFO as the surface argument is refused at once (not waited on), in the one wording
    of every input (asperity::input::open_regular, which topography::read_file now uses)."""
    import os

    fifo = tmp_path / "f.txt"
    os.mkfifo(fifo)
    for command, extra in [("contact", ["--modulus", "1e9", "--pressures", "1e5"]),
                           ("stats", []), ("bem", ["--pressures", "0.01"])]:
        args = ["--surface", fifo] if command == "bem" else [fifo]
        theirs = cli_error(cli(command, *args, *extra, ok=False))
        ours = python_words(lambda: asperity.read_topography(fifo))
        assert ours == theirs, command
        assert ours == f"{fifo}: is a FIFO, socket or device, not a regular file; give a file"


def test_one_load_of_a_solve_is_the_front_end_layers_rule(heights):
    """Solver.solve and fd_stiffness take exactly one load (asperity_app::bem::one_load;
    Python's alone: the CLI solves sweeps, whose rule is the BEM table's "give one of")."""
    solver = asperity.Solver(heights[0])
    for call, what in [(solver.solve, "solve"), (solver.fd_stiffness, "fd_stiffness")]:
        for loads in [{}, dict(pressure=0.01, force=0.01), dict(force=0.1, indentation=0.1)]:
            words = python_words(lambda: call(**loads))
            assert words == f"{what}: give exactly one of pressure=, force= or indentation="
    assert solver.solve(force=0.01, fields=False).force == pytest.approx(0.01, rel=1e-12)


def test_patches_refuse_a_pixel_area_by_the_shared_rule():
    contact_set = np.array([[1, 1, 0], [0, 0, 1]], dtype=bool)
    for bad, shown in [(0, "0"), (-1, "-1"), (NAN, "NaN"), (INF, "infinity"), (-1e-6, "-1e-6")]:
        words = python_words(lambda: asperity.patches(contact_set, pixel_area=bad))
        assert words == f"pixel_area must be positive and finite, got {shown}"
    p = asperity.patches(contact_set, pixel_area=0.25)
    assert p.areas.tolist() == [0.5, 0.25] and p.points.tolist() == [2, 1]
