"""The README's notebook example runs as written and finds the known answer."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_notebook_example_recovers_the_inputs_that_made_the_measurement():
    section = README.read_text().split("## From a notebook", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    scope: dict = {}
    exec(compile(code, str(README), "exec"), scope)
    summary = scope["summary"].set_index("parameter")
    for name, truth in {"a": 0.4, "b": 0.5}.items():
        assert summary.loc[name, "q05"] < truth < summary.loc[name, "q95"], summary
    assert summary.loc["a", "q95"] - summary.loc["a", "q05"] < 0.25     # the data do inform a
    assert len(scope["draws"]) == 10000 and scope["info"]["ess_kish"] >= 1500
