"""Property-based fuzzing (Hypothesis) of three more readers of a user's files: the
contact file, the laboratory table and a free-rocking decay (through ``contact``).  Whatever
a file holds, the reader returns a valid result or one InputError (the CLI: exit 2 and one
line), never another exception, and the CLI writes nothing when it refuses."""
import json
import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pipeline import cli
from pipeline.files import InputError
from pipeline.records.readers import lab_table
from pipeline.scenario.contact_file import CONTACT_KEYS, contact_values

FUZZ = settings(max_examples=120, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])
SCALARS = (st.none() | st.booleans() | st.integers(-10 ** 12, 10 ** 12)
           | st.sampled_from([0, -1, 10 ** 400, 1e308, -0.0, 0.05, 1e8])
           | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=10))
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=3)
                      | st.dictionaries(st.text(max_size=8), inner, max_size=3),
                      max_leaves=8)
NUMBER_TEXT = (st.floats(allow_nan=True, allow_infinity=True).map(repr)
               | st.sampled_from(["inf", "nan", "1e999", "", "0", "-0", "1e-320", "0x10", "١"])
               | st.text(alphabet="0123456789.-e, \t", max_size=8))


def one_line(message, name):
    assert message and len(message.splitlines()) == 1 and len(message) < 1000, message
    assert name in message, message


CONTACT_DOCUMENTS = (st.dictionaries(st.sampled_from(CONTACT_KEYS + ("restitution", "x")),
                                     SCALARS, max_size=5)
                     | VALUES)


@FUZZ
@given(document=CONTACT_DOCUMENTS)
def test_fuzz_contact_file(tmp_path, document):
    path = tmp_path / "contact.json"
    try:
        path.write_text(json.dumps(document))
    except ValueError:
        return
    try:
        values = contact_values(path)
    except InputError as exc:
        one_line(str(exc), path.name)
        return
    assert {"kn", "damping"} <= set(values)
    assert all(isinstance(v, float) and math.isfinite(v) for v in values.values())


def _lab_text(units, axes, rows):
    head = ["# lab-table: fuzz", f"# units: {units}", f"# axes: {axes}"]
    return "\n".join(head + [" ".join(row) for row in rows]) + "\n"


@FUZZ
@given(units=st.sampled_from(["g", "m/s^2", "furlongs", ""]),
       axes=st.sampled_from(["90", "90 0", "90 0 up", "400", "up up", ""]),
       rows=st.lists(st.lists(NUMBER_TEXT, min_size=0, max_size=4), max_size=30))
def test_fuzz_lab_table(tmp_path, units, axes, rows):
    path = tmp_path / "test.txt"
    path.write_text(_lab_text(units, axes, rows), encoding="utf-8",
                    errors="surrogatepass")
    try:
        result = lab_table.read(path)
    except InputError as exc:
        one_line(str(exc), path.name)
        return
    assert result is not None


@FUZZ
@given(header=st.sampled_from(["time_s,tilt_rad", "time_s,tilt_deg", "tilt_rad", "a,b", ""]),
       rows=st.lists(st.tuples(NUMBER_TEXT, NUMBER_TEXT), max_size=40))
def test_fuzz_free_rocking_through_contact(tmp_path, capsys, header, rows):
    path = tmp_path / "decay.csv"
    path.write_text(header + "\n" + "".join(f"{a},{b}\n" for a, b in rows),
                    encoding="utf-8", errors="surrogatepass")
    out = tmp_path / "contact.json"
    out.unlink(missing_ok=True)
    code = cli.main(["contact", "--free-rocking", str(path), "--block", "0.40,0.08",
                     "--out", str(out)])
    err = capsys.readouterr().err
    assert code in (0, 2), err
    if code == 2:
        one_line(err.strip(), "")
        assert err.startswith("error: ")
        assert not out.exists()
    else:
        assert out.is_file()


def test_a_lab_table_without_rows_is_one_line_and_no_warning(tmp_path, recwarn):
    path = tmp_path / "empty.txt"
    path.write_text(_lab_text("g", "90", []))
    try:
        lab_table.read(path)
    except InputError as exc:
        one_line(str(exc), path.name)
        assert "0 samples" in str(exc)
    else:
        raise AssertionError("an empty table was read")
    assert not [w for w in recwarn if issubclass(w.category, UserWarning)]
