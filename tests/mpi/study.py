"""The Python side of tests/mpi/run.sh: a study through the package, run alone or under
`mpirun -n K python tests/mpi/study.py ...`. Every rank writes its result (rows and
tasks as JSON) to RESULT.<rank>, which must be the same on every rank and for every K (one
file per rank: the launcher may interleave long lines of several ranks' stdout).

Usage: study.py alpha|long|tangential OUT [RESULT]
"""
import os
import json
import sys

import asperity

kind, out = sys.argv[1], sys.argv[2]
if kind == "alpha":  # the same study as run.sh's `study alpha` on the CLI
    result = asperity.study_alpha(method="bem", n=[32, 48], hurst=[0.5, 0.8], samples=7,
                                  seed=3, out=out)
elif kind == "long":  # the same study as run.sh's long one
    result = asperity.study_alpha(method="bem", n=96, hurst=[0.5, 0.9], samples=16, seed=8,
                                  out=out)
elif kind == "tangential":  # the same study as run.sh's `study curve --poisson` (issue 37)
    result = asperity.study_curve(method="bem", n=32, hurst=[0.2, 1.0], samples=5, rolloff=4,
                                  poisson=0.3, resistivity=[1, 1], out=out)
    assert "tangential_ratio" in result.rows[0] and "electrical_conductance" in result.rows[0]
else:
    raise SystemExit(f"unknown study {kind!r}")
if len(sys.argv) > 3:
    rank = os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0"))
    with open(f"{sys.argv[3]}.{rank}", "w") as f:
        json.dump({"rows": result.rows, "tasks": result.tasks}, f, sort_keys=True)
