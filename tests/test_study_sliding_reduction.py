"""The sliding reduction in studies (issue 24 item 2): each run's row carries its rigid
companion's peaks, and ``study summary`` gives the ratios per intensity and friction.

Checked against independent references:
- each row's rigid columns equal a direct ``run_rack`` of the same rack, scaled record and
  pallets held with ``RIGID_MU`` (and are shared by the runs of the same record and intensity);
- the summary's statistics equal the mean and the sample standard deviation of ln(ratio)
  computed here from the stored rows (the lognormal dispersion, as in Baker 2015 for
  fragility); the figure file is written;
- a study stored before these columns existed still summarises (no reduction section).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from seisrack.studies import load_study, read_runs, run_study
from seisrack.studies.summary import summarize
from test_study_spec import make_study

BODY = """
racks = ["rack.toml"]
seed = 3
[records]
folder = "records"
[intensity]
measure = "pga"
unit = "g"
stripes = [0.3, 0.5]
[friction]
values = [0.2, 0.4]
"""


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory):  # noqa: ANN201
    src = make_study(tmp_path_factory.mktemp("study"), BODY)
    out = tmp_path_factory.mktemp("out")
    s = run_study(load_study(src), out, workers=1, progress=False)
    assert s.runs_ok == 8
    return src, out, read_runs(out).to_pylist()


def test_rows_carry_the_rigid_companion(study) -> None:  # noqa: ANN001
    from seisrack.analysis import run_rack
    from seisrack.design.sliding_reduction import response_peaks, rigid_model
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import Record, read_record
    from seisrack.studies import expand

    src, _, rows = study
    runs = {r.run_id: r for r in expand(load_study(src))}
    row = rows[0]
    r = runs[row["run_id"]]
    rec = read_record(src.parent / "records" / f"{r.record}.csv")
    model = compile_rack(load_rack(src.parent / "rack.toml"))
    p = response_peaks(run_rack(rigid_model(model), Record(rec.accel * r.scale_factor, rec.dt),
                                dt=0.005))
    assert row["rigid_base_shear_N"] == pytest.approx(p["base_shear_N"], rel=1e-9)
    assert row["rigid_connector_moment_Nm"] == pytest.approx(p["connector_moment_Nm"], rel=1e-9)
    assert row["rigid_upright_moment_Nm"] == pytest.approx(p["upright_moment_Nm"], rel=1e-9)
    assert row["rigid_alpha"] == pytest.approx(p["level_acceleration_m_s2"] / model.g, rel=1e-9)
    # one rigid companion per (record, intensity): the same for both friction values
    same = [x for x in rows if x["record"] == row["record"] and x["stripe"] == row["stripe"]]
    assert len(same) == 2
    assert same[0]["rigid_base_shear_N"] == same[1]["rigid_base_shear_N"]
    for x in rows:  # sliding never raises the pallets' load above the rigid one here
        assert 0 < x["base_shear_N"] / x["rigid_base_shear_N"] <= 1.0 + 1e-9


def test_summary_reduction_statistics(study) -> None:  # noqa: ANN001
    _, out, rows = study
    s = summarize(out, n_boot=0)
    red = s["groups"][0]["sliding_reduction"]
    assert red["n_runs"] == 8
    assert len(red["rows"]) == 4  # 2 intensities x 2 friction values
    for row in red["rows"]:
        sel = [x for x in rows if x["mu_static"] == row["mu_static"]
               and math.isclose(x["im_target"], row["im"])]
        ratio = np.array([x["connector_moment_Nm"] / x["rigid_connector_moment_Nm"]
                          for x in sel])
        st = row["connector_moment"]
        assert st["n"] == len(sel) == 2
        assert st["mean"] == pytest.approx(ratio.mean(), rel=1e-12)
        assert st["beta"] == pytest.approx(np.log(ratio).std(ddof=1), rel=1e-9)
    # low friction at high intensity reduces more than high friction at low intensity
    by = {(round(r["im"], 3), r["mu_static"]): r["base_shear"]["mean"] for r in red["rows"]}
    keys = sorted(by)
    assert by[keys[-2]] <= by[keys[1]] + 1e-12  # (0.5 g, 0.2) vs (0.3 g, 0.4)
    assert Path(s["files"]["sliding_reduction_png"]).read_bytes()[:4] == b"\x89PNG"
    pts = red["points"]
    assert len(pts["mu_over_alpha"]) == 8
    assert pts["mu_over_alpha"][0] == pytest.approx(pts["mu_static"][0] / pts["alpha"][0])


def test_summary_text_and_json_cli(study, capsys) -> None:  # noqa: ANN001
    from seisrack.studies.summary import summary_main

    _, out, _ = study
    assert summary_main([str(out), "--boot", "0", "--no-plots"]) == 0
    text = capsys.readouterr().out
    assert "sliding reduction" in text and "E_D1·E_D2·E_D3" in text
    assert summary_main([str(out), "--boot", "0", "--no-plots", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert "sliding_reduction" in js["groups"][0]


def test_old_store_without_rigid_columns(study, tmp_path) -> None:  # noqa: ANN001
    import pyarrow.parquet as pq

    _, out, _ = study
    (tmp_path / "runs").mkdir()
    for i, p in enumerate(sorted((out / "runs").glob("part-*.parquet"))):
        t = pq.read_table(p)
        t = t.drop_columns([c for c in t.column_names if c.startswith("rigid_")
                            or c in ("connector_moment_Nm", "upright_moment_Nm")])
        pq.write_table(t, tmp_path / "runs" / f"part-{i}.parquet")
    s = summarize(tmp_path, n_boot=0, plots=False)
    assert s["runs_ok"] == 8 and "sliding_reduction" not in s["groups"][0]


def test_study_report_reduction_section(study, tmp_path) -> None:  # noqa: ANN001
    pytest.importorskip("matplotlib")
    from seisrack.studies.summary import summary_main

    _, out, _ = study
    html = tmp_path / "s.html"
    assert summary_main([str(out), "--boot", "0", "--report", str(html)]) == 0
    text = html.read_text(encoding="utf-8")
    assert '<section id="sliding-reduction">' in text
    assert 'id="fig-sliding-reduction-0"' in text and "E_D1·E_D2·E_D3" in text
    s = json.loads((out / "summary" / "summary.json").read_text())
    mean = s["groups"][0]["sliding_reduction"]["rows"][0]["base_shear"]["mean"]
    assert f'data-value="{json.dumps(mean)}"' in text
