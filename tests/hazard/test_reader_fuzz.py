"""Property-based fuzzing (Hypothesis) of the readers survival takes a user's files
through: fragility.json (a column campaign's and a pulse grid's), the plain hazard table,
the USGS web service's JSON and OpenQuake's hazard-curve CSV.  Whatever a file holds, the
reader returns a valid object or raises one InputError whose message is one line naming
the file; never another exception.  What loads is used: a fragility gives probabilities
in [0, 1], a hazard curve positive finite levels within 100 g and rates that do not
rise."""
import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard import load_hazard
from pipeline.hazard.curves import HazardCurve
from pipeline.hazard.fragility import load_campaign_fragility

from tests.hazard.test_reader_robustness import COLUMN, USGS_DOC, grid_document

FUZZ = settings(max_examples=150, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])
SCALARS = (st.none() | st.booleans() | st.integers(-10 ** 12, 10 ** 12)
           | st.sampled_from([0, -1, 1, 10 ** 9, 10 ** 400, 1e308, -0.0, 0.5, 2.0])
           | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=12))
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4)
                      | st.dictionaries(st.text(max_size=8), inner, max_size=4),
                      max_leaves=12)
NUMBER_TEXT = (st.floats(allow_nan=True, allow_infinity=True).map(repr)
               | st.sampled_from(["inf", "-inf", "nan", "1e999", "", " ", "0", "-0", "1e-320",
                                  "0x10", "1_0", "1e308", "١"])
               | st.text(max_size=8))


def paths(value, prefix=()):
    """Every key path into a parsed JSON document (the root included)."""
    yield prefix
    items = value.items() if isinstance(value, dict) else \
        enumerate(value) if isinstance(value, list) else ()
    for key, child in items:
        yield from paths(child, prefix + (key,))


def mutate(document, data):
    """The document with the value at one key path replaced by anything, or deleted."""
    document = copy.deepcopy(document)
    where = data.draw(st.sampled_from(list(paths(document))))
    if not where:
        return data.draw(VALUES)
    parent = document
    for key in where[:-1]:
        parent = parent[key]
    if isinstance(parent, dict) and data.draw(st.booleans()):
        del parent[where[-1]]
    else:
        parent[where[-1]] = data.draw(VALUES)
    return document


def write(directory, name, content):
    path = Path(directory) / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content if isinstance(content, str) else json.dumps(content),
                        encoding="utf-8", errors="surrogatepass")
    return path


def refused_in_one_line(exc, path):
    message = str(exc)
    assert message and len(message.splitlines()) == 1 and len(message) < 2000, message
    assert path.name in message, message


def check_fragility_loads(path, form):
    try:
        fragility = load_campaign_fragility(path, None, form)
    except InputError as exc:
        refused_in_one_line(exc, path)
        return
    pga = np.geomspace(0.01, 200.0, 25)
    ratio = np.geomspace(0.005, 5.0, 25)
    p = fragility.probability(pga, ratio) if fragility.uses_ratio else \
        fragility.probability(pga)
    assert np.isfinite(p).all() and (p >= 0).all() and (p <= 1).all()
    rng = np.random.default_rng(0)
    for drawn in (fragility.draws(3, rng) or []):
        q = drawn.probability(pga, ratio) if drawn.uses_ratio else drawn.probability(pga)
        assert not np.isnan(q).any()


@pytest.mark.parametrize("form", ["pga", "pga-pgv"])
@FUZZ
@given(data=st.data())
def test_column_fragility_file_with_any_value_changed(tmp_path, form, data):
    path = write(tmp_path, "fragility.json", mutate(COLUMN, data))
    check_fragility_loads(path, form)


@pytest.mark.parametrize("form", ["grid", "pga-pgv"])
@FUZZ
@given(data=st.data())
def test_pulse_grid_file_with_any_value_changed(tmp_path, form, data):
    path = write(tmp_path, "fragility.json", mutate(grid_document(), data))
    check_fragility_loads(path, form)


@FUZZ
@given(content=VALUES | st.binary(max_size=200) | st.text(max_size=200))
def test_fragility_file_of_anything(tmp_path, content):
    check_fragility_loads(write(tmp_path, "fragility.json", content), None)


def check_hazard_loads(path):
    try:
        curve = load_hazard(path)
    except InputError as exc:
        refused_in_one_line(exc, path)
        return
    assert isinstance(curve, HazardCurve)
    levels, rates = curve.levels_m_s2, curve.rates_per_yr
    assert len(levels) >= 2 and np.isfinite(levels).all() and (levels > 0).all()
    assert (levels <= 100 * STANDARD_GRAVITY).all() and (np.diff(levels) > 0).all()
    assert np.isfinite(rates).all() and (rates > 0).all() and (np.diff(rates) <= 0).all()
    json.dumps(curve.source, allow_nan=False)           # survival.json takes it as it is


@FUZZ
@given(header=st.sampled_from(["pga_g,annual_rate_per_yr", "pga_m_s2,annual_rate_per_yr",
                               "pga_cm_s2,annual_rate_per_yr", "pgv_g,annual_rate_per_yr",
                               "pga_g,annual_rate_per_yr,x", "pga_g"]) | st.text(max_size=30),
       rows=st.lists(st.tuples(NUMBER_TEXT, NUMBER_TEXT), max_size=8),
       extra=st.sampled_from(["", "# a comment\n", "\n\n", "a,b,c\n"]))
def test_plain_hazard_table_of_any_values(tmp_path, header, rows, extra):
    text = header + "\n" + extra + "".join(f"{x},{r}\n" for x, r in rows)
    check_hazard_loads(write(tmp_path, "curve.csv", text))


@FUZZ
@given(data=st.data())
def test_usgs_json_with_any_value_changed(tmp_path, data):
    check_hazard_loads(write(tmp_path, "usgs.json", mutate(USGS_DOC, data)))


OQ_HEADER = "#,,,\"generated_by='OpenQuake engine 3.20', kind='mean', investigation_time=50.0, " \
            "imt='PGA'\""
OQ_COLUMNS = ["lon", "lat", "depth", "poe-0.0100000", "poe-0.1000000", "poe-0.5000000"]
OQ_ROW = ["172.63", "-43.53", "0.0", "5.9E-03", "5.3E-03", "3.9E-05"]


@FUZZ
@given(data=st.data())
def test_openquake_csv_with_any_cell_changed(tmp_path, data):
    header, columns, row = OQ_HEADER, list(OQ_COLUMNS), list(OQ_ROW)
    for _ in range(data.draw(st.integers(1, 3))):
        part = data.draw(st.sampled_from(["header", "column", "value"]))
        if part == "header":
            header = data.draw(st.sampled_from([
                header.replace("50.0", "1e999"), header.replace("50.0", "nan"),
                header.replace("50.0", "-1"), header.replace("PGA", "SA(0.1)"),
                header.replace("investigation_time", "time"), "#", "",
                header + data.draw(st.text(max_size=10))]))
        elif part == "column":
            k = data.draw(st.integers(0, len(columns) - 1))
            columns[k] = data.draw(st.sampled_from(["poe-inf", "poe-nan", "poe-1e308",
                                                    "poe--1", "PGA-0.2:float32", "SA(0.1)-0.2",
                                                    "poe-", "x"]) | st.text(max_size=10))
        else:
            k = data.draw(st.integers(0, len(row) - 1))
            row[k] = data.draw(NUMBER_TEXT)
    text = "\n".join([header, ",".join(columns), ",".join(row)]) + "\n"
    check_hazard_loads(write(tmp_path, "oq.csv", text))


def test_the_fuzzed_documents_load_unchanged(tmp_path):
    """The fuzzing starts from files that load (else it would test refusals only)."""
    for form in ("pga", "pga-pgv"):
        load_campaign_fragility(write(tmp_path, "c.json", COLUMN), None, form)
    load_campaign_fragility(write(tmp_path, "g.json", grid_document()))
    assert math.isclose(load_hazard(write(tmp_path, "u.json", USGS_DOC)).rates_per_yr[0], 0.1)
    text = "\n".join([OQ_HEADER, ",".join(OQ_COLUMNS), ",".join(OQ_ROW)]) + "\n"
    assert load_hazard(write(tmp_path, "oq.csv", text)).source["investigation_time_yr"] == 50.0
