"""OpenQuake's magnitude-distance disaggregation as the engine exports it: the bins read
back against the file's own numbers (pandas, apart from the loader) and against the
same calculation's curves; one-line errors for bad files."""
import numpy as np
import pandas as pd
import pytest

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.curves import load_hazard
from pipeline.hazard.disaggregation import BIN_SUM_TOLERANCE, load_mag_dist

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
MEAN = CASE / "disaggregation" / "Mag_Dist-mean-0_7.csv"
PER_RLZ = CASE / "disaggregation" / "Mag_Dist-0_7.csv"
CASE_19 = (RECORDS_DIR / "hazard" / "openquake_logictree_case_19" / "disaggregation"
           / "Mag_Dist-mean-0_16.csv")


def test_bins_as_the_file_states_them():
    table = pd.read_csv(PER_RLZ, skiprows=1)
    dis = load_mag_dist(PER_RLZ)
    assert dis.columns == ("rlz0", "rlz1") and dis.investigation_time_yr == 1.0
    assert dis.site == (11.202, 42.424)
    np.testing.assert_allclose(dis.levels_m_s2 / STANDARD_GRAVITY, sorted(set(table["iml"])))
    assert dis.bin_rates_per_yr.shape == (2, 3, 7, 15)
    for c, name in enumerate(dis.columns):
        for k, (iml, rows) in enumerate(table.groupby("iml")):
            np.testing.assert_allclose(dis.level_rates()[c, k],
                                       -np.log1p(-rows[name]).sum(), rtol=1e-12)
    row = table.iloc[40]          # one bin, found by its centre
    m = int((row["mag"] - 4.0) // 0.5)
    d = int(row["dist"] // 20.0)
    k = sorted(set(table["iml"])).index(row["iml"])
    assert dis.bin_rates_per_yr[1, k, m, d] == pytest.approx(-np.log1p(-row["rlz1"]))


def test_the_mean_adds_up_to_its_levels_poe_and_to_the_mean_curve():
    dis = load_mag_dist(MEAN)           # checked on loading against the file's poe
    np.testing.assert_allclose(dis.poes, [1e-2, 1e-3, 1e-4])   # poes_disagg, by level
    dis.check_curve("mean", load_hazard(CASE / "hazard_curve-mean-PGA_6.csv"))
    case_19 = load_mag_dist(CASE_19)    # iml_disagg: its poe is the curve's at 0.2 g
    assert case_19.levels_m_s2 == pytest.approx([0.2 * STANDARD_GRAVITY])


def test_each_realisation_adds_up_to_its_own_curve():
    dis = load_mag_dist(PER_RLZ)
    for k in (0, 1):
        dis.check_curve(f"rlz{k}", load_hazard(CASE / f"hazard_curve-rlz-00{k}-PGA_6.csv"))
    with pytest.raises(InputError, match="column rlz0: the bins at PGA"):
        dis.check_curve("rlz0", load_hazard(CASE / "hazard_curve-rlz-001-PGA_6.csv"))


def _edited(tmp_path, source, edit):
    lines = source.read_text().splitlines()
    path = tmp_path / source.name
    path.write_text("\n".join(edit(lines)) + "\n")
    return path


def _scale_mean(lines, factor):
    out = lines[:2]
    for line in lines[2:]:
        *head, value = line.split(",")
        out.append(",".join(head + [f"{float(value) * factor:.5E}"]))
    return out


def test_bins_that_do_not_add_up_to_their_level_are_refused(tmp_path):
    inside = 1 + 0.5 * BIN_SUM_TOLERANCE
    load_mag_dist(_edited(tmp_path, MEAN, lambda lines: _scale_mean(lines, inside)))
    outside = 1 + 2 * BIN_SUM_TOLERANCE
    with pytest.raises(InputError, match=r"column mean: the bins at PGA .* add up to .* "
                                         r"the file's poe gives"):
        load_mag_dist(_edited(tmp_path, MEAN, lambda lines: _scale_mean(lines, outside)))


@pytest.mark.parametrize("edit, message", [
    (lambda ls: [ls[0].replace("investigation_time=1.0, ", "")] + ls[1:],
     "no investigation_time"),
    (lambda ls: [ls[0].replace("mag_bin_edges", "mags")] + ls[1:], "no mag_bin_edges"),
    (lambda ls: ls[:2] + [ls[2].replace("PGA", "PGV", 1)] + ls[3:], "is of 'PGV'"),
    (lambda ls: ls[:2] + [ls[2]] + ls[2:], "repeats PGA"),
    (lambda ls: ls[:-1], "rows; 3 level"),
    (lambda ls: ls[:2] + [ls[2].replace("4.25000E+00", "4.30000E+00")] + ls[3:],
     "mag 4.3 is no bin's centre"),
    (lambda ls: ls[:2] + [ls[2][:-11] + "1.00000E+00"] + ls[3:], "outside"),
    (lambda ls: ls[:2] + [ls[2][:-11] + "nan"] + ls[3:], "not a number"),
    (lambda ls: [ls[0], "imt,iml,poe,magnitude,dist,mean"] + ls[2:], "expected imt,iml"),
])
def test_bad_files_get_one_line(tmp_path, edit, message):
    with pytest.raises(InputError, match=message) as info:
        load_mag_dist(_edited(tmp_path, MEAN, edit))
    assert "\n" not in str(info.value)
