"""Property-based fuzzing (Hypothesis) of the Mag_Dist reader: whatever a mutated export
holds, the reader returns a valid disaggregation or raises one InputError whose message
is one line naming the file; never another exception.  What loads has non-negative,
finite bin rates."""
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pipeline import RECORDS_DIR
from pipeline.files import InputError
from pipeline.hazard.disaggregation import load_mag_dist

SOURCE = (RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / "disaggregation"
          / "Mag_Dist-0_7.csv").read_text().splitlines()
TOKENS = st.one_of(st.text(max_size=12), st.sampled_from(
    ["nan", "inf", "-1", "1.0", "0", "1e309", "", "PGV", "[", "]", "4.25000E+00", ",,"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr))


@st.composite
def mutated(draw):
    lines = list(SOURCE)
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["field", "drop", "copy", "cut"]))
        k = draw(st.integers(0, len(lines) - 1))
        if kind == "field":
            fields = lines[k].split(",")
            j = draw(st.integers(0, len(fields) - 1))
            fields[j] = draw(TOKENS)
            lines[k] = ",".join(fields)
        elif kind == "drop":
            del lines[k]
        elif kind == "copy":
            lines.insert(k, lines[draw(st.integers(0, len(lines) - 1))])
        else:
            lines[k] = lines[k][:draw(st.integers(0, len(lines[k])))]
        if not lines:
            break
    return "\n".join(lines) + "\n"


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=mutated())
def test_a_mutated_export_loads_or_fails_in_one_line(tmp_path, text):
    path = tmp_path / "Mag_Dist-0_1.csv"
    path.write_text(text)
    try:
        dis = load_mag_dist(path)
    except InputError as exc:
        message = str(exc)
        assert "\n" not in message and str(path) in message
        return
    assert np.all(np.isfinite(dis.bin_rates_per_yr)) and np.all(dis.bin_rates_per_yr >= 0)
    assert np.all(dis.levels_m_s2 > 0)
