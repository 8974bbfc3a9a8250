"""Contact fields as NetCDF (issue 36 item 3): results saved as `.nc` load back identical,
the CLI's `bem --fields FILE.nc` holds the numbers Python's file holds, and other NetCDF
readers (scipy; xarray where installed) read the files with their CF attributes."""

import json

import numpy as np
import pytest

import asperity

from test_round_trips import _same_columns


@pytest.fixture(scope="module")
def surface():
    return asperity.surface(32, hurst=0.8, rolloff=2, rms_slope=1.0, seed=4)


def test_results_saved_as_netcdf_load_back_identical(tmp_path, surface):
    capped = asperity.Solver(surface, boundary="periodic", hardness=0.3)
    result = capped.solve(pressure=0.03)
    assert result.plastic_points > 0
    result.save(tmp_path / "r.nc")
    back = asperity.load(tmp_path / "r.nc")
    assert isinstance(back, asperity.ContactResult)
    for name in ("pressure", "gap", "displacement", "plastic_displacement"):
        saved, loaded = getattr(result, name), getattr(back, name)
        assert loaded.dtype == saved.dtype and loaded.shape == (32, 32), name
        assert loaded.tobytes() == saved.tobytes(), name
    for name in ("force", "mean_pressure", "indentation", "area_fraction", "contact_points",
                 "iterations", "residual", "plastic_fraction", "plastic_points"):
        assert getattr(back, name) == getattr(result, name), name
    assert back.metadata == result.metadata

    # A sweep with its field stacks; a column with NaN ("not computed", as stiffness_fd
    # at indentation 0).
    sweep = capped.sweep(pressures=[0.01, 0.03], fields=True)
    sweep.save(tmp_path / "fields.nc")
    _same_columns(asperity.load(tmp_path / "fields.nc"), sweep)
    plain = asperity.Solver(surface).sweep(nloads=3, pmin=1e-3, pmax=1e-2)
    plain.columns["stiffness_fd"] = np.array([np.nan, 2.5, np.nan])
    plain.save(tmp_path / "plain.nc")
    _same_columns(asperity.load(tmp_path / "plain.nc"), plain)

    # A load path: branch names and the permanent displacement.
    path = asperity.Solver(surface, boundary="periodic", hardness=0.3).load_path(
        pressures=[0.01, 0.03, 0.01])
    path.save(tmp_path / "path.nc")
    _same_columns(asperity.load(tmp_path / "path.nc"), path)

    # An SI contact: contact set (bool), patch labels (uint32), patch areas (own dimension).
    c = asperity.contact(surface.heights * 1e-6, 1e-4, young=210e9, poisson=0.3,
                         pressures=[1e6, 1e7], map=True)
    c.save(tmp_path / "c.nc")
    _same_columns(asperity.load(tmp_path / "c.nc"), c)


def test_the_cli_and_python_write_the_same_fields(cli, tmp_path, surface):
    surface.save(tmp_path / "s.npy")
    cli("bem", "--surface", tmp_path / "s.npy", "--pressures", "0.01,0.03",
        "--fields", tmp_path / "cli.nc", "--quiet")
    sweep = asperity.Solver(surface).sweep(pressures=[0.01, 0.03], fields=True)
    sweep.save(tmp_path / "py.nc")
    ours, theirs = asperity.load(tmp_path / "py.nc"), asperity.load(tmp_path / "cli.nc")
    for name in ("pressure", "gap"):
        for a, b in zip(ours[name], theirs[name]):
            assert a.tobytes() == b.tobytes(), name
    for name in ("force", "mean_pressure", "indentation", "area_fraction"):
        assert ours[name].tobytes() == theirs[name].tobytes(), name
    assert theirs.metadata["command"] == "asperity bem"


def test_scipy_reads_the_file_with_its_cf_attributes(tmp_path, surface):
    netcdf = pytest.importorskip("scipy.io").netcdf_file
    c = asperity.contact(surface.heights * 1e-6, 1e-4, young=210e9, poisson=0.3,
                         pressures=[1e6, 1e7], map=True)
    c.save(tmp_path / "c.nc")
    plain = asperity.Solver(surface).sweep(nloads=3, pmin=1e-3, pmax=1e-2, fields=True)
    plain.columns["stiffness_fd"] = np.array([np.nan, 2.5, np.nan])
    plain.save(tmp_path / "plain.nc")
    with netcdf(tmp_path / "c.nc", "r", mmap=False) as f:
        assert f.Conventions == b"CF-1.8"
        assert json.loads(f.asperity_record)["metadata"] == c.metadata
        x, y = f.variables["x"], f.variables["y"]
        assert x.units == b"m" and x.length == 1e-4 and x.axis == b"X"
        np.testing.assert_array_equal(x[:], np.arange(32) * (1e-4 / 32))
        assert f.variables["force_n"].units == b"N"
        assert f.variables["mean_pressure_pa"].units == b"Pa"
        np.testing.assert_array_equal(f.variables["force_n"][:], c.force_n)
        contact = f.variables["map"]
        assert contact.dimensions == ("y", "x") and list(contact.flag_values) == [0, 1]
        np.testing.assert_array_equal(contact[:].astype(bool), c.map)
        assert f.variables["patch_areas_m2"].dimensions == ("patch",)
    with netcdf(tmp_path / "plain.nc", "r", mmap=False) as f:
        p = f.variables["pressure"]
        assert p.dimensions == ("load", "y", "x") and p.long_name == b"contact pressure"
        assert not hasattr(p, "units")  # E* units: the user's
        assert p.comment == b"in the units of the modulus E*"
        np.testing.assert_array_equal(p[:], np.stack(plain.pressure))
        fd = f.variables["stiffness_fd"]
        assert fd._FillValue == 9.969209968386869e36  # NaN (not computed): CF fill value
        np.testing.assert_array_equal(fd[:], [fd._FillValue, 2.5, fd._FillValue])


def test_xarray_decodes_the_file(tmp_path, surface):
    xr = pytest.importorskip("xarray")
    plain = asperity.Solver(surface).sweep(nloads=3, pmin=1e-3, pmax=1e-2, fields=True)
    plain.columns["stiffness_fd"] = np.array([np.nan, 2.5, np.nan])
    plain.save(tmp_path / "plain.nc")
    with xr.open_dataset(tmp_path / "plain.nc") as ds:
        assert ds["pressure"].dims == ("load", "y", "x")
        np.testing.assert_array_equal(ds["pressure"].values, np.stack(plain.pressure))
        np.testing.assert_array_equal(ds["stiffness_fd"].values, [np.nan, 2.5, np.nan])


def test_bad_requests_are_refused_in_one_line(tmp_path, surface):
    sweep = asperity.Solver(surface).sweep(pressures=[0.01], fields=True)
    with pytest.raises(ValueError, match=r"must end in \.npz .* or \.nc") as e:
        sweep.save(tmp_path / "a.cdf")
    assert "\n" not in str(e.value)
    sweep.save(tmp_path / "a.nc")
    before = (tmp_path / "a.nc").read_bytes()
    with pytest.raises(ValueError, match="exists"):
        sweep.save(tmp_path / "a.nc")
    assert (tmp_path / "a.nc").read_bytes() == before
    sweep.save(tmp_path / "a.nc", force=True)
    # A map without the surface's sides cannot have coordinates.
    bare = asperity.Sweep({"force": np.ones(1), "pressure": [np.ones((2, 2))]}, {})
    with pytest.raises(ValueError, match="no side length"):
        bare.save(tmp_path / "bare.nc")
    assert not (tmp_path / "bare.nc").exists()
    # A map holds no NaN: refused before anything is written.
    broken = asperity.Sweep({"force": np.ones(1), "pressure": [np.full((2, 2), np.nan)]},
                            {"size": 1.0})
    with pytest.raises(ValueError, match="non-finite"):
        broken.save(tmp_path / "broken.nc")
    assert not (tmp_path / "broken.nc").exists()
    # A damaged file: one line, no Python traceback from the reader.
    (tmp_path / "cut.nc").write_bytes(before[: len(before) // 2])
    with pytest.raises(ValueError) as e:
        asperity.load(tmp_path / "cut.nc")
    assert "\n" not in str(e.value)


def test_a_netcdf_topography_still_loads_as_one():
    from test_topography import shared

    path = shared("../topographies-3/nc-1.nc")
    t = asperity.load(path)
    assert isinstance(t, asperity.Topography)
    assert t.heights.ndim == 2 and t.size > 0
