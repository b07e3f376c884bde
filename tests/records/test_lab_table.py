"""Laboratory table motions: the values written come back in East/North/Up and m/s^2;
malformed tables are one-line errors."""
import gzip

import numpy as np
import pytest

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records import read_east_north_up, resolve
from pipeline.records.readers import read_record


def table(path, header, rows):
    text = "\n".join(header) + "\n" + "\n".join(" ".join(f"{v:.9g}" for v in r) for r in rows)
    if path.suffix == ".gz":
        path.write_bytes(gzip.compress(text.encode()))
    else:
        path.write_text(text + "\n")
    return path


def samples(n=400, dt=0.005, columns=1):
    t = dt * np.arange(n)
    values = [np.sin(2 * np.pi * (k + 1) * t) * (0.1 + 0.05 * k) for k in range(columns)]
    return t, values


@pytest.mark.parametrize("axes, units, scale, east, north, up", [
    ("90", "g", STANDARD_GRAVITY, 0, None, None),
    ("270", "g", STANDARD_GRAVITY, 0, None, None),
    ("0", "m/s^2", 1.0, None, 0, None),
    ("90 0 up", "m/s^2", 1.0, 0, 1, 2),
])
def test_components_come_back_where_the_axes_say(tmp_path, axes, units, scale, east, north,
                                                 up):
    n_cols = len(axes.split())
    t, values = samples(columns=n_cols)
    path = table(tmp_path / "lab.txt.gz", ["# lab-table: test", f"# units: {units}",
                                           f"# axes: {axes}"],
                 np.column_stack([t] + values))
    enu, dt, info, _ = read_east_north_up(resolve(str(path)))
    assert info["format"] == "lab-table"
    assert dt == pytest.approx(0.005)
    sign = -1.0 if axes.startswith("270") else 1.0
    for k, column in enumerate((east, north, up)):
        if column is None:
            assert np.abs(enu[:, k]).max() < 1e-12   # a uniaxial table: the others are zero
        else:
            assert enu[:, k] == pytest.approx(sign ** (k == 0) * scale * values[column],
                                              rel=1e-7, abs=1e-9)   # 9 digits written
    if n_cols == 1:
        assert len(info["zero_components"]) == 2


@pytest.mark.parametrize("header, rows, words", [
    (["# lab-table: x", "# axes: 90"], None, "units"),
    (["# lab-table: x", "# units: g"], None, "axes"),
    (["# lab-table: x", "# units: furlong", "# axes: 90"], None, "units"),
    (["# lab-table: x", "# units: g", "# axes: 400"], None, "outside"),
    (["# lab-table: x", "# units: g", "# axes: 90 0"], None, "columns"),
    (["# lab-table: x", "# units: g", "# axes: 90 95"], "two", "not independent"),
    (["# lab-table: x", "# units: g", "# axes: up"], None, "horizontal"),
    (["# lab-table: x", "# units: g", "# axes: 90"], "jitter", "uniformly"),
    (["# lab-table: x", "# units: g", "# axes: 90"], "short", "at least 100"),
    (["# lab-table: x", "# units: g", "# axes: 90"], "nan", "NaN"),
])
def test_malformed_tables_are_one_line_errors(tmp_path, header, rows, words):
    t, (a,) = samples()
    data = np.column_stack([t, a])
    if rows == "two":
        data = np.column_stack([t, a, a])
    elif rows == "jitter":
        data[5, 0] += 0.002
    elif rows == "short":
        data = data[:50]
    elif rows == "nan":
        data[7, 1] = np.nan
    path = table(tmp_path / "bad.txt", header, data)
    with pytest.raises(InputError, match=words) as info:
        read_record(path)
    assert "\n" not in str(info.value)


def test_a_byte_order_mark_before_the_header_is_passed_over(tmp_path):
    t, (a,) = samples()
    plain = table(tmp_path / "plain.txt", ["# lab-table: x", "# units: g", "# axes: 90"],
                  np.column_stack([t, a]))
    marked = tmp_path / "marked.txt"
    marked.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    stream, info = read_record(marked)
    assert info["format"] == "lab-table"
    assert stream[0].data == pytest.approx(read_record(plain)[0][0].data, rel=0, abs=0)


@pytest.mark.parametrize("units, peak, refused", [("g", 19.9, False), ("g", 59_000.0, True),
                                                  ("m/s^2", 300.0, True)])
def test_accelerations_beyond_a_table_s_reach_are_refused(tmp_path, units, peak, refused):
    # 20 g: beyond any shake table or recorded earthquake (~4 g); 59,000 g is a table in
    # other units than its header says
    t, (a,) = samples()
    path = table(tmp_path / "lab.txt", ["# lab-table: x", f"# units: {units}", "# axes: 90"],
                 np.column_stack([t, a / np.abs(a).max() * peak]))
    if not refused:
        assert np.abs(read_record(path)[0][0].data).max() == pytest.approx(
            peak * STANDARD_GRAVITY, rel=1e-6)
        return
    with pytest.raises(InputError, match="beyond the 20 g a lab table may reach") as info:
        read_record(path)
    assert "\n" not in str(info.value)
