"""The joint hazard of PGA and PGV read from OpenQuake's mean rate density (``mrd``) of
its QA case postproc/case_mrd, checked against the same calculation's curves (exported
by the engine as CSV, read by the project's curve loader); one-line errors for bad files."""
import json
import shutil

import h5py
import numpy as np
import pandas as pd
import pytest

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.curves import load_hazard
from pipeline.hazard.joint_hazard import JointHazard, load_joint_hazard

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
MRD = CASE / "mrd_pga_pgv.hdf5"
MRD_OTHER_IMTS = CASE / "mrd_pga_sa0.05.hdf5"
ENGINE_ABS_TOLERANCE = 1.5e-4   # the engine's own test: assert_almost_equal(decimal=4), 1/yr
RELATIVE = 0.01                 # on every interval holding >= 1e-6 of the total rate


def test_levels_sites_and_units_as_the_file_states_them():
    joint = load_joint_hazard(MRD)
    with h5py.File(MRD, "r") as f:
        params = json.loads(f["oqparam"][()])
        lon, lat = f["sitecol/lon"][0], f["sitecol/lat"][0]
    assert joint.sites == ((float(lon), float(lat)),)
    assert joint.investigation_time_yr == params["investigation_time"] == 1.0
    np.testing.assert_allclose(joint.pga_levels_m_s2,
                               np.array(params["hazard_imtls"]["PGA"]) * STANDARD_GRAVITY)
    np.testing.assert_allclose(joint.pgv_levels_m_s,
                               np.array(params["hazard_imtls"]["PGV"]) / 100.0)
    assert joint.cell_rates_per_yr.shape == (1, 39, 39)
    assert joint.source["engine_version"] == "3.26.2"


def test_summed_over_pgv_the_mrd_gives_back_the_pga_curve():
    """The engine's own test of compute_mrd: the marginal over the second IMT equals the
    first IMT's curve, interval by interval (here the engine's exported CSV)."""
    joint = load_joint_hazard(MRD)
    curve = load_hazard(CASE / "hazard_curve-mean-PGA_6.csv")
    n = curve.levels_m_s2.size          # the CSV's curve ends at its last positive rate
    np.testing.assert_allclose(curve.levels_m_s2, joint.pga_levels_m_s2[:n], rtol=1e-3)
    from_curve = -np.diff(curve.rates_per_yr)
    from_mrd = joint.pga_interval_rates()[0, :n - 1]
    assert np.max(np.abs(from_mrd - from_curve)) < ENGINE_ABS_TOLERANCE
    held = from_curve >= 1e-6 * curve.rates_per_yr[0]
    assert held.sum() >= 20
    np.testing.assert_allclose(from_mrd[held], from_curve[held], rtol=RELATIVE)


def test_summed_over_pga_the_mrd_gives_the_pgv_curve_where_pga_is_on_the_grid():
    """The axes the right way round: above 0.5 mm/s of PGV no event has PGA below the
    grid's first level (0.0001 g), and the marginal over PGA is the PGV curve."""
    joint = load_joint_hazard(MRD)
    table = pd.read_csv(CASE / "hazard_curve-mean-PGV_6.csv", skiprows=1)
    levels_cm_s = np.array([float(c.split("-", 1)[1]) for c in table.columns[3:]])
    rates = -np.log1p(-table.iloc[0, 3:].to_numpy(float))
    np.testing.assert_allclose(levels_cm_s / 100.0, joint.pgv_levels_m_s, rtol=1e-3)
    from_curve = -np.diff(rates)
    from_mrd = joint.cell_rates_per_yr[0].sum(axis=0)
    held = (levels_cm_s[:-1] >= 0.05) & (from_curve >= 1e-6 * rates[0])
    assert held.sum() >= 10
    np.testing.assert_allclose(from_mrd[held], from_curve[held], rtol=RELATIVE)


def test_an_mrd_of_other_intensity_measures_is_refused():
    with pytest.raises(InputError, match=r"of PGA and SA\(0.05\); .* needs PGA and PGV"):
        load_joint_hazard(MRD_OTHER_IMTS)


def test_a_site_beyond_the_file_is_refused():
    joint = load_joint_hazard(MRD)
    assert joint.site(0).source["site_index"] == 0
    with pytest.raises(InputError, match="site 1 beyond the file's 1 site"):
        joint.site(1)


def _copy(tmp_path, edit):
    path = tmp_path / "calc.hdf5"
    shutil.copyfile(MRD, path)
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


def _set_params(f, change):
    params = json.loads(f["oqparam"][()])
    change(params)
    del f["oqparam"]
    f.create_dataset("oqparam", data=json.dumps(params).encode())


def test_levels_that_do_not_match_the_mrd_are_refused(tmp_path):
    def drop_a_level(f):
        _set_params(f, lambda p: p["hazard_imtls"].update(PGV=p["hazard_imtls"]["PGV"][1:]))
    with pytest.raises(InputError, match="39 x 39 cells; the levels of PGV and PGA make "
                                         "38 x 39"):
        load_joint_hazard(_copy(tmp_path, drop_a_level))


@pytest.mark.parametrize("edit, message", [
    (lambda f: f.__delitem__("mrd"), "no dataset 'mrd'"),
    (lambda f: (f.__delitem__("mrd"), f.create_group("mrd")), "no dataset 'mrd'"),
    (lambda f: (f.__delitem__("oqparam"), f.create_group("oqparam")), "no 'oqparam'"),
    (lambda f: (f.__delitem__("mrd"), f.create_dataset("mrd", data=np.zeros((39, 39)))),
     "2 dimensions, not 3"),
    (lambda f: _set_params(f, lambda p: p.__setitem__("postproc_args", ["PGA"])),
     "the mrd is of None and None"),
    (lambda f: f.__delitem__("sitecol/lat"), "no sitecol/lon and sitecol/lat"),
    (lambda f: f["mrd"].__setitem__((0, 0, 0), -1.0), "a negative rate"),
    (lambda f: f["mrd"].__setitem__((0, 0, 0), np.nan), "not a finite number"),
    (lambda f: _set_params(f, lambda p: p["hazard_imtls"]["PGA"].reverse()),
     "PGA levels do not increase"),
    (lambda f: _set_params(f, lambda p: p.update(investigation_time=None)),
     "investigation time"),
])
def test_bad_datastores_get_one_line(tmp_path, edit, message):
    with pytest.raises(InputError, match=message) as info:
        load_joint_hazard(_copy(tmp_path, edit))
    assert "\n" not in str(info.value)


def test_not_an_hdf5_file_and_a_missing_file(tmp_path):
    text = tmp_path / "mrd.hdf5"
    text.write_text("lon,lat\n")
    with pytest.raises(InputError, match="not an HDF5 file"):
        load_joint_hazard(text)
    with pytest.raises(InputError, match="not found"):
        load_joint_hazard(tmp_path / "none.hdf5")


def test_the_type_checks_itself():
    levels = np.array([1.0, 2.0, 4.0])
    with pytest.raises(InputError, match="the levels and sites make"):
        JointHazard(levels, levels, np.zeros((1, 3, 2)), 1.0, ((0.0, 0.0),))
    with pytest.raises(InputError, match="not a coordinate"):
        JointHazard(levels, levels, np.zeros((1, 2, 2)), 1.0, ((0.0, 95.0),))
