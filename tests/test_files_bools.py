"""CSV booleans read back in one place (pipeline.files.csv_true)."""
import numpy as np
import pandas as pd

from pipeline.files import csv_true, csv_true_column


def test_csv_true_reads_what_pandas_and_json_write():
    for value in (True, np.bool_(True), "True", "true", " TRUE "):
        assert csv_true(value) is True
    for value in (False, np.bool_(False), "False", "", "1", None, float("nan"), 1):
        assert csv_true(value) is False
    frame = pd.read_csv(pd.io.common.StringIO("a\nTrue\nFalse\n\n"), skip_blank_lines=False)
    assert csv_true_column(frame["a"]).tolist() == [True, False, False]
