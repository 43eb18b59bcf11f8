"""Tables on disk: Parquet with metadata, CSV accepted, clear errors."""

import pandas as pd
import pytest

from shockcal.errors import InputError
from shockcal.io import read_table, read_table_metadata, require_columns, write_table


def test_parquet_round_trip_keeps_list_columns_and_metadata(tmp_path):
    df = pd.DataFrame({"run": [0, 1], "v_m_s": [[0.0, 1.5], [2.0, 3.0]]})
    path = write_table(df, tmp_path / "sub" / "t.parquet", {"units": {"v_m_s": "m/s"}})
    back = read_table(path)
    assert back["v_m_s"].map(list).tolist() == [[0.0, 1.5], [2.0, 3.0]]
    meta = read_table_metadata(path)
    assert meta.pop("provenance")["shockcal_version"]           # every table says what wrote it (test_provenance.py)
    assert meta == {"units": {"v_m_s": "m/s"}}
    assert [p.name for p in path.parent.iterdir()] == ["t.parquet"]  # no temporary left behind


def test_csv_is_accepted(tmp_path):
    (tmp_path / "t.csv").write_text("run,A\n0,0.5\n")
    assert read_table(tmp_path / "t.csv")["A"].tolist() == [0.5]


def test_errors_name_the_file(tmp_path):
    with pytest.raises(InputError, match="nothere.parquet does not exist"):
        read_table(tmp_path / "nothere.parquet")
    (tmp_path / "t.xlsx").write_text("x")
    with pytest.raises(InputError, match="t.xlsx: unknown format"):
        read_table(tmp_path / "t.xlsx")
    (tmp_path / "broken.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="broken.parquet could not be read"):
        read_table(tmp_path / "broken.parquet")
    with pytest.raises(InputError, match=r"f.csv: missing column\(s\) \['B'\]"):
        require_columns(pd.DataFrame({"A": [1]}), ["A", "B"], "f.csv")
