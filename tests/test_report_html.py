"""The engineer's HTML report (seisrack.report.html) and ``seisrack report``, without a browser:
self-contained file, the numbers of summary.json in the tables, overwrite and bad-path errors,
static fallback without plotly. ``test_report_browser.py`` renders it in Chromium."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def build_case(mu: float | None = None, seconds: float = 6.0) -> dict:
    """The three-level example rack under the first seconds of the bundled El Centro record."""
    from seisrack.analysis import run_rack
    from seisrack.checks import run_design_checks
    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack, load_rack, with_friction
    from seisrack.motion import Record, ec8_spectrum, load_builtin_record

    spec = load_rack(EXAMPLES / "three_level_rack.toml")
    if mu is not None:
        spec = with_friction(spec, mu)
    model = compile_rack(spec)
    full = load_builtin_record("elcentro_1940_ns")
    n = int(round(seconds / full.dt)) + 1
    rec = Record(np.asarray(full.accel[:n]), full.dt, name="elcentro_first_6s")
    resp = run_rack(model, rec)
    modal = modal_analysis(model, n_modes=4)
    design = ec8_spectrum(1, "C", 0.3)
    checks = run_design_checks(model, resp, modal=modal, spectrum=design, record=rec)
    summary = {"rack": "examples/three_level_rack.toml", "title": spec.title, **resp.summary()}
    summary["design_checks"] = checks
    # as summary.json holds it (JSON round trip: tuples -> lists, inf -> Infinity)
    summary = json.loads(json.dumps(summary, default=float))
    return dict(spec=spec, model=model, response=resp, record=rec, summary=summary,
                modal=modal, checks=checks, design_spectrum=design)


def build_case_3d(seconds: float = 8.0) -> dict:
    """The 3D paper rack under two components (El Centro 1940 NS x 3 along both axes at 30°),
    with the rigid companion run: pallets slide and fall into the aisles."""
    from seisrack.analysis import run_rack
    from seisrack.checks import run_design_checks
    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import Record, ec8_spectrum, load_builtin_record
    from seisrack.motion.components import combine

    spec = load_rack(EXAMPLES / "paper_rack_3d.toml")
    model = compile_rack(spec)
    full = load_builtin_record("elcentro_1940_ns")
    n = int(round(seconds / full.dt)) + 1
    rec = Record(3.0 * np.asarray(full.accel[:n]), full.dt, name="elcentro_x3")
    motion = combine(rec, rec, angle_deg=30.0)
    resp = run_rack(model, motion, rigid_companion=True)
    modal = modal_analysis(model, n_modes=6)
    design = ec8_spectrum(1, "C", 0.3)
    checks = run_design_checks(model, resp, modal=modal, spectrum=design, record=motion)
    summary = {"rack": "examples/paper_rack_3d.toml", "title": spec.title, **resp.summary()}
    summary["design_checks"] = checks
    summary = json.loads(json.dumps(summary, default=float))
    return dict(spec=spec, model=model, response=resp, record=motion, summary=summary,
                modal=modal, checks=checks, design_spectrum=design)


def test_3d_report_has_the_plan_view_falls_and_both_directions(tmp_path):
    """The same report for a 3D rack: plan view, falls into the aisles, both record
    components, the checks in both directions, the modal classes."""
    pytest.importorskip("matplotlib")
    from seisrack.report.html import write_html_report

    case = build_case_3d()
    resp = case["response"]
    assert resp.falls, "this motion must drop pallets"
    text = write_html_report(tmp_path / "r3.html", **case).read_text(encoding="utf-8")
    for fig in ("fig-elevation", "fig-plan", "fig-modes", "fig-record", "fig-spectrum"):
        assert f'id="{fig}"' in text, fig
    assert text.count('<tr data-fall="') == len(resp.falls)
    assert "cross-aisle" in text and "down-aisle mass [%]" in text
    assert "record (cross-aisle)" in text and "incidence angle" in text
    drift = case["checks"]["checks"][-1]
    assert {r["direction"] for r in drift["storeys"]} == {"down-aisle", "cross-aisle"}
    fem = case["checks"]["checks"][0]
    lv = fem["levels"][0]
    # the two directions combined by SRSS
    assert lv["a_uls_m_s2"] == pytest.approx(np.hypot(lv["a_uls_down_aisle_m_s2"],
                                                      lv["a_uls_cross_aisle_m_s2"]), rel=1e-12)
    assert case["summary"]["simplified_check"]["assessed"] is True
    assert f"{len(resp.falls)} pallet(s) fall into an aisle" in text


@pytest.fixture(scope="module")
def case():
    pytest.importorskip("matplotlib")
    return build_case()


def test_report_is_self_contained_with_every_section(case, tmp_path):
    from seisrack.report.html import write_html_report

    out = write_html_report(tmp_path / "r.html", **case, rack_file="rack.toml", seed=7)
    text = out.read_text(encoding="utf-8")
    for sec in ("inputs", "elevation", "modal", "record", "histories", "tables", "checks"):
        assert f'<section id="{sec}">' in text
    # elastic connections: no "Connections" section, the checks keep their number
    assert '<section id="connections">' not in text and "7. Design checks" in text
    # no external resource: every src is inline, no stylesheet links, no remote scripts
    assert not re.search(r'<(script|img|link|iframe)[^>]+(src|href)="(https?:)?//', text)
    assert "<link" not in text
    assert text.count('src="data:image/png;base64,') >= 4
    assert "seisrack version" in text and ">7<" in text  # the seed
    # every figure has a caption
    assert text.count("<figure") == text.count("<figcaption>")
    assert "@page { size: A4" in text and "break-before: page" in text
    # a value not assessed (the paper's rule without --rigid-check, a factor not set) reads
    # "–" in a client's deliverable, not Python's None
    assert ">None<" not in text


def test_tables_hold_the_numbers_of_summary(case, tmp_path):
    from seisrack.report.html import write_html_report

    text = write_html_report(tmp_path / "r.html", **case).read_text(encoding="utf-8")
    s = case["summary"]
    for j, p in enumerate(s["pallets"]):
        row = re.search(rf'<tr[^>]*data-pallet="{j}">(.*?)</tr>', text, re.S).group(1)
        for key in ("peak_sliding_m", "residual_m", "fall_utilisation", "mass_kg"):
            val = re.search(rf'data-key="{key}" data-value="([^"]+)"', row).group(1)
            assert json.loads(val) == p[key]
    per = s["peaks"]["per_level"]
    for i in range(len(per["beam_displacement_m"])):
        row = re.search(rf'<tr data-level="{i}">(.*?)</tr>', text, re.S).group(1)
        for key, vals in per.items():
            val = re.search(rf'data-key="{key}" data-value="([^"]+)"', row).group(1)
            assert json.loads(val) == vals[i]


def test_disagreement_is_flagged(case, tmp_path):
    from seisrack.report.html import write_html_report

    text = write_html_report(tmp_path / "r.html", **case).read_text(encoding="utf-8")
    if case["checks"]["disagreements"]:
        assert "Checks that disagree with the time history" in text
    for c in case["checks"]["checks"]:
        assert f'id="check-{c["name"]}"' in text


def test_refuses_to_overwrite_without_force(case, tmp_path):
    from seisrack.report.html import write_html_report

    path = tmp_path / "r.html"
    path.write_text("old")
    with pytest.raises(InputError, match=re.escape(str(path))):
        write_html_report(path, **case)
    assert path.read_text() == "old"
    write_html_report(path, **case, force=True)
    assert path.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_unwritable_path_is_a_clear_error(case, tmp_path):
    from seisrack.report.html import write_html_report

    # a missing folder is created (issue 23: as `seisrack run --out` does)
    assert write_html_report(tmp_path / "no" / "such" / "r.html", **case).is_file()
    (tmp_path / "afile").write_text("")
    with pytest.raises(InputError, match="is a file, not a folder"):
        write_html_report(tmp_path / "afile" / "r.html", **case)
    with pytest.raises(InputError, match="folder"):
        write_html_report(tmp_path, **case)
    if os.geteuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o500)
        with pytest.raises(InputError, match="writable"):
            write_html_report(ro / "r.html", **case)


def test_static_fallback_without_plotly(case, tmp_path):
    from seisrack.report.html import write_html_report

    text = write_html_report(tmp_path / "r.html", **case, interactive=False).read_text(
        encoding="utf-8")
    assert "<script" not in text
    assert re.search(r'<figure id="fig-histories"><img src="data:image/png;base64,', text)


def test_cli_report_writes_html_and_summary(tmp_path, capsys):
    from seisrack.cli import main

    out = tmp_path / "rep" / "report.html"
    out.parent.mkdir()
    rc = main(["report", str(EXAMPLES / "three_level_rack.toml"), "--builtin",
               "elcentro_1940_ns", "--ec8", "1", "C", "0.3", "--out", str(out), "--json"])
    assert rc == 0
    printed = json.loads(capsys.readouterr().out)
    on_disk = json.loads((out.parent / "summary.json").read_text())
    assert printed["design_checks"]["checks"][0]["name"] == "pallet_sliding_fem"
    assert on_disk["pallets"] == printed["pallets"]
    assert out.stat().st_size > 0
    # a second run refuses to overwrite, --force overwrites
    assert main(["report", str(EXAMPLES / "three_level_rack.toml"), "--builtin",
                 "elcentro_1940_ns", "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert main(["report", str(EXAMPLES / "three_level_rack.toml"), "--builtin",
                 "elcentro_1940_ns", "--out", str(out), "--force"]) == 0


def test_cli_report_scales_the_record_and_runs_the_rigid_check(tmp_path, capsys):
    """--scale-pga reaches the run (its ground peak equals the target) and the report;
    --rigid-check makes alpha come from the rigid-pallet run."""
    from seisrack.cli import main

    out = tmp_path / "report.html"
    rc = main(["report", str(EXAMPLES / "paper_rack.toml"), "--builtin", "elcentro_1940_ns",
               "--scale-pga", "2.5", "--rigid-check", "--out", str(out), "--json"])
    assert rc == 0
    s = json.loads(capsys.readouterr().out)
    assert s["scaling"]["method"] == "pga"
    assert s["scaling"]["pga_after"] == pytest.approx(2.5, rel=1e-12)
    assert s["simplified_check"]["alpha_source"].startswith("rigid companion run")
    assert "scaling" in out.read_text(encoding="utf-8")
    (tmp_path / "bad").mkdir()
    assert main(["report", str(EXAMPLES / "paper_rack.toml"), "--builtin", "elcentro_1940_ns",
                 "--scale-pga", "-1", "--out", str(tmp_path / "bad" / "x.html")]) == 2
    assert "--scale-pga" in capsys.readouterr().err


def test_cli_report_refuses_a_summary_folder_before_writing_anything(tmp_path, capsys):
    """``summary.json`` beside the report is a folder: even with ``--force`` the command stops
    with the usual error before it writes the report (it used to leave ``report.html``
    behind and then fail on the summary)."""
    from seisrack.cli import main

    out = tmp_path / "report.html"
    (tmp_path / "summary.json").mkdir()
    assert main(["report", str(EXAMPLES / "three_level_rack.toml"), "--builtin",
                 "elcentro_1940_ns", "--out", str(out), "--force"]) == 2
    err = capsys.readouterr().err
    assert "summary.json" in err and "folder" in err and "Traceback" not in err
    assert not out.exists()
    assert (tmp_path / "summary.json").is_dir()
