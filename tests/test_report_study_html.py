"""The study's HTML report (``seisrack study summary DIR --report FILE.html``).

The study store is synthetic (as in ``test_study_summary.py``): a rack on 4 PGA stripes with 8
records x 2 friction samples and 3 failed runs, plus a second rack analysed by IDA, and a
``study.json`` in the format ``seisrack study`` writes. Checked: the file is self-contained,
every figure has a caption, every number cell's ``data-value`` equals the value of
``summary.json`` at its ``data-path``, the fitted-parameter table is the fragility list of
summary.json, non-ok statuses are explained, and an existing report is not overwritten without
``--force``. The browser test (Chromium through Playwright, same helpers as
``test_report_browser.py``) fails on a console error, checks every figure rendered and reads the
table numbers back from the DOM.
"""

from __future__ import annotations

import html
import json
import math
import re

import numpy as np
import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("matplotlib")

from test_study_summary import _row, _write, summary_main  # noqa: E402

G = 9.80665
IMS = (1.0, 2.0, 3.0, 4.0)  # [m/s²]
STUDY_TOML = """title = "Synthetic study"
racks = ["paper.toml", "ida.toml"]
dt = 0.005
seed = 2026

[records]
builtin = ["elcentro_1940_ns"]

[intensity]
measure = "pga"
unit = "m/s2"
stripes = [1.0, 2.0, 3.0, 4.0]

[friction]
dist = "lognormal"
median = 0.4
dispersion = 0.2
samples = 2
"""


def build_store(root):
    """Stripes on paper.toml (64 ok + 3 failed runs) and 7 IDA curves on ida.toml."""
    rng = np.random.default_rng(11)
    rows, i = [], 0
    for s, x in enumerate(IMS):
        for rec in range(8):
            for m in range(2):
                cap = 2.5 * math.exp(0.4 * rng.standard_normal())
                slide = 0.05 * x / cap
                rows.append(_row(i, record=f"rec{rec}", im_target=x, stripe=s,
                                 scale_factor=x / (1.0 + 0.1 * rec), mu_static=0.3 + 0.1 * m,
                                 peak_sliding_max_m=slide, any_fall=bool(slide > 0.1),
                                 n_fall=int(slide > 0.1), base_shear_N=1000.0 * x + rec))
                i += 1
    for err in ("solver: max events exceeded", "record: NaN in accelerogram",
                "solver: max events exceeded"):
        rows.append(_row(i, record="recX", im_target=IMS[3], stripe=3, status="failed",
                         error=err, peak_sliding_max_m=None, pallet_peak_sliding_m=None,
                         any_fall=None, n_fall=None, base_shear_N=None))
        i += 1
    for rec, c in enumerate([1.2, 1.7, 2.2, 0.8, 2.7, 1.4, 1.9]):
        for x in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0):
            rows.append(_row(i, rack="ida.toml", record=f"rec{rec}", stripe=-1, im_target=x,
                             peak_sliding_max_m=0.05 * x / c))
            i += 1
    _write(root, rows)
    study = {"format": "seisrack-study/1", "source": "examples/synthetic_study.toml",
             "study_toml": STUDY_TOML, "title": "Synthetic study",
             "racks": ["paper.toml", "ida.toml"], "dt": 0.005, "seed": 2026,
             "intensity": {"measure": "pga", "levels_m_s2": list(IMS), "kind": "stripes"},
             "runs": [{k: r[k] for k in ("run_id", "rack", "record", "im_target",
                                         "scale_factor", "stripe", "mu_static")}
                      for r in rows]}
    (root / "study.json").write_text(json.dumps(study))
    return root


ARGS = ["--boot", "40", "--d-slide", "0.05", "--shear-capacity", "3500", "--no-plots"]


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    root = build_store(tmp_path_factory.mktemp("study"))
    report = root / "study.html"
    assert summary_main([str(root), *ARGS, "--report", str(report)]) == 0
    summary = json.loads((root / "summary" / "summary.json").read_text())
    gs = [i for i, g in enumerate(summary["groups"]) if "stripes" in g]
    gi = [i for i, g in enumerate(summary["groups"]) if "ida" in g]
    assert len(gs) == len(gi) == 1
    return dict(root=root, report=report, text=report.read_text(encoding="utf-8"),
                summary=summary, gs=gs[0], gi=gi[0])


def _at(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def _cells(text):
    """(path, value) of every number cell of the page."""
    out = []
    for m in re.finditer(r"<td [^>]*data-path=\"([^\"]+)\"[^>]*data-value=\"([^\"]*)\"", text):
        out.append((json.loads(html.unescape(m.group(1))), json.loads(html.unescape(m.group(2)))))
    return out


def test_self_contained_with_every_section(study):
    text = study["text"]
    for sec in ("inputs", "runs", "stripes", "fragility", "parameters", "ida"):
        assert f'<section id="{sec}">' in text
    assert not re.search(r'(src|href)\s*=\s*"(https?:)?//', text)
    assert "<link" not in text and "<script" not in text and "<iframe" not in text
    assert "@page { size: A4" in text and "break-before: page" in text
    # every figure is an inline PNG with a caption; one fragility figure per damage state
    figs = re.findall(r'<figure id="([^"]+)"><img src="data:image/png;base64,[^"]+"', text)
    assert text.count("<figure") == text.count("<figcaption>") == len(figs)
    states = study["summary"]["damage_states"]
    assert states == ["sliding>0.05m", "any_fall", "base_shear>3500N"]
    gs, gi = study["gs"], study["gi"]
    assert {f"fig-fragility-{gs}-{k}" for k in range(len(states))} <= set(figs)
    assert f"fig-ida-{gi}" in figs and f"fig-ida-fragility-{gi}-0" in figs
    for cap in re.findall(r"<figcaption>(.*?)</figcaption>", text, re.S):
        assert "[m/s²]" in cap or "[mm]" in cap, cap  # units in every caption
    assert "5-95 % bootstrap band" in text  # the bands of the stripes' fits are drawn


def test_the_summary_warnings_are_read_first(study):
    """Runs left out of the statistics (stored for another definition of the study, or
    missing from the store) are said before the first section, as in the summary's text."""
    from seisrack.report.html.study_page import build_study_html

    assert 'id="warnings"' not in study["text"]  # a complete study: nothing to say
    note = "3 stored runs are left out: they are not runs of the study"
    text = build_study_html(dict(study["summary"], warnings=[note]))
    assert text.index('id="warnings"') < text.index('<section id="inputs">')
    assert html.unescape(text).count(note) == 1


def test_inputs_name_the_study(study):
    text = html.unescape(study["text"])
    inputs = text.split('<section id="runs">')[0]
    for want in ("examples/synthetic_study.toml", "paper.toml, ida.toml", "pga",
                 "dist = lognormal, median = 0.4, dispersion = 0.2, samples = 2",
                 "study 2026", "bootstrap 0 (40 resamples)", "seisrack version", "rec7",
                 "Study file as given", "0.102 g"):
        assert want in inputs, want
    # records and their scale factors per level (from study.json)
    row = re.search(r"<tr><td>paper.toml</td><td>rec1</td><td>([^<]+)</td>", inputs).group(1)
    assert row.startswith(f"{1.0 / G:.3g} g → ×{1.0 / 1.1:.4g}")


def test_every_number_is_the_value_of_summary_json(study):
    s, cells = study["summary"], _cells(study["text"])
    assert len(cells) > 150
    for path, value in cells:
        assert value == _at(s, path), path
    paths = {tuple(p) for p, _ in cells}
    assert ("runs_failed",) in paths and ("failure_reasons", "solver: max events exceeded") in paths
    gs = study["gs"]
    st = s["groups"][gs]["stripes"]["stripes"]
    for si in range(len(st)):
        for d in s["damage_states"]:
            assert ("groups", gs, "stripes", "stripes", si, "fraction", d) in paths
        for k in st[si]["peaks"]:
            for c in ("mean", "max", "ec8"):
                assert ("groups", gs, "stripes", "stripes", si, "peaks", k, c) in paths


def test_parameter_table_equals_summary_json(study):
    s, text = study["summary"], study["text"]
    table = re.search(r'<table id="table-fragility">(.*?)</table>', text, re.S).group(1)
    rows = re.findall(r'<tr data-fit="(\d+)">(.*?)</tr>', table, re.S)
    assert [int(i) for i, _ in rows] == list(range(len(s["fragility"])))
    assert len(rows) == 6  # 3 states x (stripes, ida)
    for i, row in rows:
        f = s["fragility"][int(i)]
        got = {p[-1]: v for p, v in _cells(row)}
        for key in ("theta", "beta", "theta_lo", "theta_hi", "beta_lo", "beta_hi",
                    "n_stripes", "n_runs"):
            assert got[key] == f[key], (i, key)
        assert f">{html.escape(f['status'])}</td>" in row
        if f["theta"] is not None:  # shown with 4 significant digits
            assert f">{f['theta']:.4g}</td>" in row
    # the statuses other than ok are explained
    bad = {f["status"] for f in s["fragility"]} - {"ok", "ida_moments"}
    assert bad >= {"separated", "no_exceedance"}
    for st in bad:
        assert f'<li id="status-{st}">' in text


def test_refuses_to_overwrite_without_force(study, capsys):
    root, report = study["root"], study["report"]
    before = report.read_bytes()
    capsys.readouterr()
    assert summary_main([str(root), *ARGS, "--report", str(report)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("seisrack: error:") and "--force" in err and "Traceback" not in err
    assert err.strip().count("\n") == 0  # one paragraph
    assert report.read_bytes() == before
    # --force rewrites it: mark the old file so the check does not hang on the clock (the
    # report's date has one-second resolution, so two writes may give identical bytes)
    report.write_bytes(before + b"<!-- old -->")
    assert summary_main([str(root), *ARGS, "--report", str(report), "--force", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["files"]["report_html"] == str(report)
    assert not report.read_bytes().endswith(b"<!-- old -->")  # rewritten


def test_cli_bad_report_path(study, tmp_path, capsys):
    from seisrack.cli import main

    (tmp_path / "afile").write_text("")
    code = main(["study", "summary", str(study["root"]), "--boot", "0", "--no-plots",
                 "--report", str(tmp_path / "afile" / "r.html")])
    err = capsys.readouterr().err
    assert code == 2 and "is a file, not a folder" in err and "Traceback" not in err
    # a missing folder is created (as `seisrack run --out` does)
    assert main(["study", "summary", str(study["root"]), "--boot", "0", "--no-plots",
                 "--report", str(tmp_path / "missing" / "r.html")]) == 0
    assert (tmp_path / "missing" / "r.html").is_file()


def test_no_bootstrap_no_band(study, tmp_path):
    from seisrack.report.html import write_study_report

    p = write_study_report(tmp_path / "r.html", study["summary"], out_dir=tmp_path)
    text = p.read_text(encoding="utf-8")
    assert "no bootstrap band" in text and "no study.json" in text


# ---------------------------------------------------------------- in a real browser


@pytest.fixture(scope="module")
def rendered(study):
    from test_report_browser import CHROMIUM, FLAGS, _need_browser

    _need_browser()
    from playwright.sync_api import sync_playwright

    shot = study["root"] / "study.png"
    errors: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}")
                if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
        page.on("request", lambda r: errors.append(f"request {r.url}")
                if not r.url.startswith(("file:", "data:")) else None)
        page.goto(study["report"].as_uri(), wait_until="load")
        page.screenshot(path=str(shot), full_page=True)
        figures = page.evaluate("""() => Array.from(document.querySelectorAll('figure')).map(f => {
            const els = Array.from(f.querySelectorAll('img'));
            return {id: f.id, caption: f.querySelector('figcaption')?.innerText ?? '',
                    sizes: els.map(e => {const r = e.getBoundingClientRect();
                        return [r.width, r.height, e.naturalWidth, e.naturalHeight, e.complete];
                    })};
        })""")
        cells = page.evaluate("""() => Array.from(document.querySelectorAll(
            'td[data-path]')).map(td => ({table: td.closest('table').id, path: td.dataset.path,
                                          value: td.dataset.value ?? null, text: td.innerText}))""")
        browser.close()
    return dict(errors=errors, figures=figures, cells=cells, shot=shot)


def test_browser_no_console_errors(rendered):
    assert rendered["errors"] == [], f"screenshot: {rendered['shot']}"


def test_browser_every_figure_rendered(rendered):
    figs = rendered["figures"]
    assert len(figs) >= 5, f"screenshot: {rendered['shot']}"
    for f in figs:
        assert f["sizes"] and f["caption"], f"{f['id']}; screenshot: {rendered['shot']}"
        for w, h, nw, nh, complete in f["sizes"]:
            assert w > 50 and h > 50 and nw > 0 and nh > 0 and complete, (
                f"figure {f['id']} {w}x{h} (natural {nw}x{nh}); screenshot: {rendered['shot']}")
    assert rendered["shot"].stat().st_size > 10_000


def test_browser_tables_hold_summary_json_numbers(rendered, study):
    s, shot = study["summary"], rendered["shot"]
    cells = [c for c in rendered["cells"] if c["value"] is not None]
    gs = study["gs"]
    assert {c["table"] for c in cells} >= {"table-runs", "table-failures", f"table-stripes-{gs}",
                                           f"table-peaks-{gs}", "table-fragility"}
    for c in cells:
        path = json.loads(c["path"])
        assert json.loads(c["value"]) == _at(s, path), f"{c}; screenshot: {shot}"
    # what the reader sees: θ with 4 significant digits, fractions with 3 decimals
    for c in cells:
        path, want = json.loads(c["path"]), _at(s, json.loads(c["path"]))
        if path[-1] == "theta" and want is not None:
            assert c["text"] == f"{want:.4g}", c
        if "fraction" in path and want is not None:
            assert c["text"] == f"{want:.3f}", c
        if path == ["runs_total"]:
            assert c["text"] == str(s["runs_total"])
