"""Studies share the CLI's checkpoint folders: a study stopped in Python resumes from the
CLI and one stopped in the CLI resumes from Python, with the numbers of an uninterrupted
run bit for bit; Ctrl-C (SIGINT) stops a long Python study within seconds, keeping its
checkpoints."""

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import asperity

from conftest import INTERRUPTIBLE, cli_path


def checkpoint_samples(folder: Path) -> int:
    """Samples held by the in-progress checkpoints of a study folder."""
    total = 0
    for path in (folder / "checkpoint").glob("*.json"):
        try:
            record = json.loads(path.read_text())
        except (OSError, ValueError):
            continue  # being replaced
        # asperity-checkpoint/2 keeps the task's state under "content".
        record = record.get("content", record)
        if record.get("state") == "in_progress":
            total += len(record["samples"])
    return total


def alpha_csv(path: Path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


class Stop(Exception):
    pass


MDR = dict(method="mdr", n=[256, 512], hurst="0:1:0.5", samples=40, seed=3)
MDR_FLAGS = ["--method", "mdr", "--n", "256,512", "--hurst", "0:1:0.5", "--samples", 40,
             "--seed", 3]


def test_an_mdr_study_equals_the_cli_and_resumes_there(cli, tmp_path):
    cli("study", "alpha", *MDR_FLAGS, "--out", tmp_path / "cli", "--quiet")
    reference = alpha_csv(tmp_path / "cli" / "alpha.csv")
    ours = asperity.study_alpha(**MDR, out=tmp_path / "py")
    for name in reference[0]:
        theirs = [r[name] for r in reference]
        mine = ours[name].tolist()
        if name == "method":
            assert mine == theirs
            continue
        # Empty CSV cells are NaN in the columns.
        mine = [None if isinstance(v, float) and np.isnan(v) else v for v in mine]
        assert mine == [float(v) if v != "" else None for v in theirs], name

    # Stopped in Python after the first batch (checkpoint after every batch)...
    def stop_after_first_batch(done, total):
        if done > 0:
            raise Stop()

    with pytest.raises(Stop):
        asperity.study_alpha(**MDR, out=tmp_path / "resumed", checkpoint_every=0,
                             progress=stop_after_first_batch)
    assert 0 < checkpoint_samples(tmp_path / "resumed") < 40
    # ... resumed by the CLI: the same table as the uninterrupted run, byte for byte.
    cli("study", "alpha", *MDR_FLAGS, "--out", tmp_path / "resumed", "--quiet")
    assert (tmp_path / "resumed" / "alpha.csv").read_bytes() == (tmp_path / "cli" / "alpha.csv").read_bytes()


def test_an_mdr_curve_study_with_rolloff_equals_the_cli(cli, tmp_path):
    """`study_curve` returns `curve.csv`'s columns (one definition of them, the front-end
    layer's), value for value, with the types the CLI writes."""
    flags = ["--method", "mdr", "--n", 512, "--hurst", "-0.5,0.5", "--samples", 10,
             "--rolloff", 6, "--levels", 20]
    cli("study", "curve", *flags, "--out", tmp_path / "cli", "--quiet")
    reference = alpha_csv(tmp_path / "cli" / "curve.csv")
    ours = asperity.study_curve(method="mdr", n=512, hurst=[-0.5, 0.5], samples=10, rolloff=6,
                                levels=20, out=tmp_path / "py")
    assert list(ours.columns) == list(reference[0])
    assert len(ours.rows) == len(reference) == 40
    assert ours["n"].dtype == np.int64 and ours["samples"].dtype == np.int64
    for name in reference[0]:
        theirs = [r[name] for r in reference]
        if name == "method":
            assert ours[name].tolist() == theirs
        else:
            assert ours[name].tolist() == [float(v) for v in theirs], name


def test_the_comparison_with_the_paper_equals_study_compare(cli, tmp_path):
    """`StudyResult.comparison()` is `asperity study compare`'s comparison.csv, row for row,
    with the verdict that the rule gives (re-derived here from the CSV: the reference
    inside [low − tol, high + tol] agrees, within 0.02 + tol is close) and that report.md
    prints."""
    cli("study", "alpha", *MDR_FLAGS, "--out", tmp_path / "cli", "--quiet")
    cli("study", "compare", tmp_path / "cli")
    with open(tmp_path / "cli" / "comparison.csv", newline="") as f:
        theirs = list(csv.DictReader(f))
    report = (tmp_path / "cli" / "report.md").read_text()
    ours = asperity.study_alpha(**MDR, out=tmp_path / "py").comparison()
    assert len(theirs) == len(ours["ours"]) == 6
    # The same columns in the same order (one list, the front-end layer's), then the verdict.
    assert list(ours) == list(theirs[0]) + ["verdict"]
    for i, row in enumerate(theirs):
        for name in ("method", "quantity", "source"):
            assert ours[name][i] == row[name], name
        for name in ("n", "hurst", "ours", "low", "high", "reference", "tolerance"):
            assert ours[name][i] == float(row[name]), name
        low, high, ref, tol = (float(row[k]) for k in ("low", "high", "reference", "tolerance"))
        verdict = ("agrees" if low - tol <= ref <= high + tol else
                   "close" if abs(float(row["ours"]) - ref) <= 0.02 + tol else "differs")
        assert ours["verdict"][i] == verdict
        assert low < float(row["ours"]) < high
    assert report.count("| agrees |") == list(ours["verdict"]).count("agrees")
    assert report.count("| differs |") == list(ours["verdict"]).count("differs")


def test_study_compare_writes_the_clis_comparison_and_report(cli, tmp_path):
    """`asperity.study_compare(folder)` is `asperity study compare folder`: the same
    comparison.csv byte for byte and the same report.md (but for the folder's name), its
    verdicts those of report.md; an existing output needs `force` (the CLI's words); a
    missing folder, or one that holds no study, is a FileNotFoundError."""
    import shutil

    cli("study", "alpha", *MDR_FLAGS, "--out", tmp_path / "a", "--quiet")
    shutil.copytree(tmp_path / "a", tmp_path / "b")
    cli("study", "compare", tmp_path / "a")
    ours = asperity.study_compare(tmp_path / "b")
    a, b = tmp_path / "a", tmp_path / "b"
    assert (a / "comparison.csv").read_bytes() == (b / "comparison.csv").read_bytes()
    report = (b / "report.md").read_text()
    assert (a / "report.md").read_text().replace(str(a), str(b)) == report
    with open(b / "comparison.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(ours["verdict"]) == len(rows) == 6
    for name in ("ours", "low", "high", "reference"):
        assert ours[name].tolist() == [float(r[name]) for r in rows], name
    assert list(ours["method"]) == [r["method"] for r in rows]
    assert report.count("| agrees |") == list(ours["verdict"]).count("agrees")
    assert report.count("| differs |") == list(ours["verdict"]).count("differs")
    assert list(ours["verdict"]) == list(
        asperity.study_alpha(**MDR, out=tmp_path / "c").comparison()["verdict"])
    # An existing output: refused by both, each naming the file (the CLI's words name its
    # flag, the package's are the library's, as for every output of the package).
    again = cli("study", "compare", a, ok=False).stderr
    assert f"{a / 'comparison.csv'}: output already exists (use --force" in again
    with pytest.raises(ValueError) as err:
        asperity.study_compare(b)
    assert str(err.value).startswith(f"{b / 'comparison.csv'}: output already exists")
    asperity.study_compare(b, force=True)
    for missing in (tmp_path / "none", tmp_path / "empty"):
        (tmp_path / "empty").mkdir(exist_ok=True)
        with pytest.raises(FileNotFoundError) as err:
            asperity.study_compare(missing)
        assert isinstance(err.value, OSError) and str(missing) in str(err.value)


def test_a_rolloff_study_is_compared_by_its_steepest_slope_as_study_compare(cli, tmp_path):
    """A roll-off study's comparison (Fig. 2: the steepest slope of the mean curve against
    the paper's "≈ 1", bootstrap interval over the stored BEM sample curves) is
    `asperity study compare`'s comparison.csv, row for row; an α study that ended its
    sweeps cannot be compared, in the CLI's words."""
    flags = ["--method", "bem", "--n", 32, "--hurst", "0.3,0.8", "--samples", 6, "--seed", 2,
             "--rolloff", 2]
    cli("study", "curve", *flags, "--out", tmp_path / "cli", "--quiet")
    cli("study", "compare", tmp_path / "cli")
    with open(tmp_path / "cli" / "comparison.csv", newline="") as f:
        theirs = list(csv.DictReader(f))
    ours = asperity.study_curve(method="bem", n=32, hurst=[0.3, 0.8], samples=6, seed=2,
                                rolloff=2, out=tmp_path / "py").comparison()
    assert len(theirs) == len(ours["ours"]) == 2
    for i, row in enumerate(theirs):
        assert ours["quantity"][i] == row["quantity"] == "steepest_slope"
        for name in ("method", "source"):
            assert ours[name][i] == row[name], name
        for name in ("n", "hurst", "ours", "low", "high", "reference", "tolerance"):
            assert ours[name][i] == float(row[name]), name
        assert ours["low"][i] < ours["ours"][i] < ours["high"][i], "a bootstrap interval"
    ended = asperity.study_alpha(method="bem", n=32, hurst=[0.8], samples=2, rolloff=2,
                                 out=tmp_path / "ended")
    refused = cli("study", "compare", tmp_path / "ended", ok=False).stderr
    with pytest.raises(ValueError, match="stopped loading past") as err:
        ended.comparison()
    assert str(err.value) in refused


BEM = dict(method="bem", n=32, hurst=[0.5], samples=16, seed=5)
BEM_FLAGS = ["--method", "bem", "--n", 32, "--hurst", 0.5, "--samples", 16, "--seed", 5]


def test_a_bem_curve_study_stopped_in_the_cli_resumes_in_python(tmp_path):
    reference = asperity.study_curve(**BEM, out=tmp_path / "reference")
    folder = tmp_path / "stopped"
    process = subprocess.Popen(
        [str(cli_path()), "study", "curve", *map(str, BEM_FLAGS), "--out", str(folder),
         "--checkpoint-every", "0", "--quiet"],
        stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while checkpoint_samples(folder) == 0 and process.poll() is None:
        assert time.monotonic() < deadline, "no checkpoint after 120 s"
        time.sleep(0.01)
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=30) == 130, process.stderr.read()
    kept = checkpoint_samples(folder)
    assert 0 < kept < 16, f"the CLI should have stopped mid-study ({kept} samples kept)"
    restored = []
    resumed = asperity.study_curve(**BEM, out=folder, progress=lambda d, t: restored.append(d))
    assert restored[0] == kept, "Python resumed from the CLI's checkpoint"
    assert resumed.rows == reference.rows
    assert resumed.tasks == reference.tasks


def test_a_bem_alpha_study_ends_its_sweeps_as_the_cli_and_fits_as_the_whole_sweep(cli, tmp_path):
    flags = ["--method", "bem", "--n", 64, "--hurst", "-1,1", "--samples", 4, "--seed", 5]
    study = dict(method="bem", n=[64], hurst=[-1.0, 1.0], samples=4, seed=5)
    cli("study", "alpha", *flags, "--out", tmp_path / "cli", "--quiet")
    # The Python study resumes in the CLI's folder: same spec (the sweep's end included).
    ours = asperity.study_alpha(**study, out=tmp_path / "cli")
    whole = asperity.study_alpha(**study, out=tmp_path / "whole", full_sweep=True)
    assert ours.rows == whole.rows
    spec = json.loads((tmp_path / "cli" / "study.json").read_text())["spec"]
    assert spec["sweep_end"] == 0.08
    assert "sweep_end" not in json.loads((tmp_path / "whole" / "study.json").read_text())["spec"]
    # Each sample's curve stops at the first load past the end, short of the 24.
    for task in ours.tasks:
        assert task["mean_curve"][-1]["fraction"] < whole_fraction(whole, task)
    # A folder holding the whole sweep's samples is resumed as that study, as by the CLI.
    with pytest.warns(UserWarning, match="resuming its study, which solves every load"):
        again = asperity.study_alpha(**study, out=tmp_path / "whole")
    assert again.rows == whole.rows
    assert "sweep_end" not in json.loads((tmp_path / "whole" / "study.json").read_text())["spec"]


def whole_fraction(whole, task):
    match = [t for t in whole.tasks if t["task"] == task["task"]]
    return match[0]["mean_curve"][-1]["fraction"]


def test_ctrl_c_stops_a_long_study_within_seconds_keeping_its_checkpoints(tmp_path):
    folder = tmp_path / "long"
    script = f"""
import sys, asperity
def report(done, total):
    if done > 0:
        print("running", flush=True)
try:
    asperity.study_alpha(method="bem", n=[256], hurst=[0.5], samples=10000, seed=1,
                         out={str(folder)!r}, checkpoint_every=0, progress=report)
except KeyboardInterrupt:
    print("KeyboardInterrupt", flush=True)
    sys.exit(130)
print("finished", flush=True)
"""
    # cwd: not python/, whose asperity/ source folder would shadow the installed package.
    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, cwd=tmp_path,
                               stderr=subprocess.PIPE, text=True, **INTERRUPTIBLE)
    assert process.stdout.readline().strip() == "running", process.stderr.read()
    assert checkpoint_samples(folder) > 0
    start = time.monotonic()
    process.send_signal(signal.SIGINT)
    code = process.wait(timeout=60)
    elapsed = time.monotonic() - start
    out = process.stdout.read()
    assert code == 130 and "KeyboardInterrupt" in out, (code, out, process.stderr.read())
    # One BEM sample of 256² (24 solves and stiffnesses) takes seconds; the samples in
    # flight stop inside their solves (the sampler's solver polls the same stop flag), so
    # the study ends within a second when idle, against hours without the stop; 20 s
    # allow for a busy machine (issue 33 item 16).
    print(f"study stopped {elapsed:.3f} s after SIGINT")
    assert elapsed < 20.0, f"took {elapsed:.2f} s to stop"
    assert (folder / "study.json").exists() and checkpoint_samples(folder) > 0


@pytest.mark.parametrize("kind", ["alpha", "curve"])
def test_a_study_s_defaults_are_the_cli_s(cli, tmp_path, kind):
    """Keywords left out take the defaults of `asperity study` (the library's
    StudySpec::default, written once): the same study.json as the CLI without those flags,
    and the same numbers."""
    cli("study", kind, "--method", "mdr", "--n", 64, "--hurst", 0.5, "--samples", 3,
        "--out", tmp_path / "cli", "--quiet")
    run = asperity.study_alpha if kind == "alpha" else asperity.study_curve
    ours = run(method="mdr", n=64, hurst=0.5, samples=3, out=tmp_path / "py")
    theirs = json.loads((tmp_path / "cli" / "study.json").read_text())
    mine = json.loads((tmp_path / "py" / "study.json").read_text())
    assert mine == theirs
    assert {"seed", "levels", "window"} <= set(mine["spec"])
    with open(tmp_path / "cli" / f"{kind}.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    name = "alpha" if kind == "alpha" else "stiffness"
    assert [float(r[name]) for r in rows] == ours[name].tolist()


def test_study_arguments_are_checked_like_the_cli(cli, tmp_path):
    message = cli("study", "alpha", "--method", "mdr", "--n", 512, "--hurst", "4", "--samples",
                  2, "--out", tmp_path / "a", ok=False).stderr
    with pytest.raises(ValueError) as err:
        asperity.study_alpha(method="mdr", n=512, hurst=4, samples=2, out=tmp_path / "b")
    assert str(err.value) in message
    with pytest.raises(ValueError, match="method must be mdr or bem, got \"fem\""):
        asperity.study_alpha(method="fem", n=512, hurst=0.5, samples=2, out=tmp_path / "c")
    with pytest.raises(ValueError, match="given twice"):
        asperity.study_alpha(method="mdr", n=[512, 512], hurst=0.5, samples=2, out=tmp_path / "d")
    message = cli("study", "alpha", "--method", "mdr", "--n", 64, "--hurst", 0.5, "--samples",
                  2, "--checkpoint-every", -1, "--out", tmp_path / "f", ok=False).stderr
    with pytest.raises(ValueError) as err:
        asperity.study_alpha(method="mdr", n=64, hurst=0.5, samples=2, checkpoint_every=-1,
                             out=tmp_path / "g")
    assert str(err.value) == "checkpoint_every must be between 0 and 1e6 seconds, got -1"
    assert str(err.value).replace("checkpoint_every", "--checkpoint-every") in message
    # Another study's folder is refused, as by the CLI.
    asperity.study_alpha(method="mdr", n=64, hurst=0.5, samples=4, out=tmp_path / "e")
    with pytest.raises(ValueError, match="holds the checkpoint of another study"):
        asperity.study_alpha(method="mdr", n=64, hurst=0.5, samples=4, seed=9, out=tmp_path / "e")


def test_a_studys_progress_weighs_samples_as_the_clis(tmp_path, monkeypatch, capsys):
    """Python's progress of a study takes the front-end layer's ETA (the CLI's arithmetic,
    asperity_app::study::progress::Eta): each sample weighs its cost (MDR: N log2 N), and
    samples read back from checkpoints do not count towards the rate."""
    from asperity import _api

    handed = []
    weigh = _api._Progress.weigh
    monkeypatch.setattr(_api._Progress, "weigh",
                        lambda self, eta: (handed.append(eta), weigh(self, eta))[1])
    study = dict(method="mdr", n=[256, 512], hurst=[0.5], samples=2, seed=3)
    asperity.study_alpha(**study, out=tmp_path / "s", progress=True)
    eta = handed[0]
    assert eta.total == 4 and eta.remaining(0, 1.0) is None
    # Both samples of N = 256 in 1 s; each of N = 512 costs (512·9)/(256·8) = 2.25 times
    # as much: 2.25 s left (counting samples alike would say 1 s).
    assert eta.remaining(2, 1.0) == pytest.approx(2.25, rel=1e-12)
    assert eta.line("mdr study", 2, 1.0) == "mdr study: 2/4 (1 s elapsed, ETA 2 s)"
    # Without tqdm, the plain line is the CLI's log line, ETA included.
    if "tqdm" not in sys.modules:
        assert "mdr study: 4/4 (" in capsys.readouterr().err
    # Resumed with every sample held: all of them restored, none done in this run.
    asperity.study_alpha(**study, out=tmp_path / "s", progress=True)
    assert handed[1].remaining(2, 1.0) is None and handed[1].remaining(4, 1.0) == 0.0
