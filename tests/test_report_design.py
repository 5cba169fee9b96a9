"""The report's design section (issue 24 items 1-2): ``seisrack report --ec8 ... --q ...
--rigid-check`` writes "Design analysis (EN 16681 / EN 1998-1 modal response spectrum)" with
the numbers of summary.json (``design_analysis``, ``sliding_reduction``) in its tables.

The values are those of seisrack.design (validated in tests/test_design_analysis.py,
tests/test_design_vs_time_history.py and tests/test_sliding_reduction.py); here the report must
show them exactly and the ratios must be the quotients of the peaks it shows.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from seisrack.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def report(tmp_path_factory):  # noqa: ANN001, ANN201
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("rep") / "report.html"
    assert main(["report", str(EXAMPLES / "paper_rack.toml"), "--builtin", "elcentro_1940_ns",
                 "--mu", "0.3", "--ec8", "1", "C", "0.3", "--q", "2", "--rigid-check",
                 "--factors", "e_d1=0.9", "--out", str(out)]) == 0
    summary = json.loads((out.parent / "summary.json").read_text())
    return out.read_text(encoding="utf-8"), summary


def _cell(text: str, key: str) -> float:
    m = re.search(rf'data-key="{re.escape(key)}" data-value="([^"]+)"', text)
    assert m, key
    return float(m.group(1))


def test_design_section_present_with_summary_numbers(report) -> None:  # noqa: ANN001
    text, summary = report
    assert '<section id="design">' in text
    assert "Design analysis (EN 16681 / EN 1998-1 modal response spectrum)" in text
    for tid in ("table-design-modes", "table-design-storeys-x", "table-design-members",
                "table-design-beside", "table-design-factors", "table-sliding-reduction"):
        assert f'id="{tid}"' in text
    da = summary["design_analysis"]
    assert da["factors"]["e_d1"] == 0.9 and da["q"] == {"down-aisle": 2.0}
    cm = da["quantities"]["connector_moment"]
    assert _cell(text, "connector_moment_design") == cm["max"]
    st = da["storeys"]["down-aisle"]["storeys"][0]
    assert _cell(text, "design_theta") == st["theta"]
    assert "assumption" in text


def test_sliding_reduction_table(report) -> None:  # noqa: ANN001
    text, summary = report
    red = summary["sliding_reduction"]
    rows = {r["quantity"]: r for r in red["rows"]}
    for key in ("base_shear", "connector_moment", "upright_moment", "pallet_force"):
        r = rows[key]
        assert r["ratio"] == pytest.approx(r["sliding"] / r["rigid"], rel=1e-12)
        assert _cell(text, f"reduction_{key}_ratio") == r["ratio"]
    # the paper rack at mu 0.3 under El Centro slides: the pallet force is capped below rigid
    assert rows["pallet_force"]["ratio"] < 1.0
    assert red["mu_over_alpha"] == pytest.approx(0.3 / red["alpha"])
    assert red["code_nominal"]["down-aisle"] == pytest.approx(0.9 * 0.8 * 1.0)
    assert 0 < red["code_rack"]["base_shear"] < 1


def test_report_without_ec8_says_how(tmp_path) -> None:  # noqa: ANN001
    pytest.importorskip("matplotlib")
    out = tmp_path / "r.html"
    assert main(["report", str(EXAMPLES / "paper_rack.toml"), "--builtin",
                 "elcentro_1940_ns", "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert '<section id="design">' in text and "Give --ec8" in text
    assert "design_analysis" not in json.loads((tmp_path / "summary.json").read_text())
