"""The HTML report rendered in a real browser: headless Chromium (Debian's ``chromium``, at
/usr/bin/chromium) driven by Playwright for Python with ``executable_path`` (Playwright's own
browser download is never used). ``make test`` installs chromium when it is missing and the user
is root.

The test fails on any console error or uncaught page error, checks that every figure rendered
(non-empty <img>, plotly <svg>, <canvas>), reads the tables back from the DOM and compares them
with summary.json, and saves a screenshot in pytest's tmp dir (its path is in every assert
message). It skips only when chromium or Playwright is missing AND the CI variable is unset.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from test_report_html import build_case, build_case_3d

CHROMIUM = os.environ.get("SEISRACK_CHROMIUM") or shutil.which("chromium") or (
    "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def _need_browser() -> None:
    """Skip (locally) or fail (CI) when the browser or Playwright is missing."""
    missing = []
    if CHROMIUM is None:
        missing.append("chromium (apt-get install chromium, or `make test` as root)")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        missing.append("playwright (pip install 'seisrack[test]')")
    if missing:
        msg = "headless browser test needs " + " and ".join(missing)
        if os.environ.get("CI"):
            pytest.fail(msg + "; CI is set, so this must run")
        pytest.skip(msg)


@pytest.fixture(scope="module", params=["2D", "3D"])
def rendered(request, tmp_path_factory):
    """Write the report and summary.json of a 2D and of a 3D rack, open it in Chromium,
    collect what the page shows."""
    _need_browser()
    pytest.importorskip("matplotlib")
    from playwright.sync_api import sync_playwright

    from seisrack.report.html import write_html_report
    from seisrack.report.rack_io import write_summary_json

    case = build_case() if request.param == "2D" else build_case_3d()
    d = tmp_path_factory.mktemp("browser")
    html = write_html_report(d / "report.html", **case)
    write_summary_json(case["summary"], d / "summary.json")
    shot = d / "report.png"
    errors: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True,
                                    args=FLAGS)
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}")
                if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
        page.goto(html.as_uri(), wait_until="load")
        page.wait_for_timeout(300)  # let plotly finish drawing
        page.screenshot(path=str(shot), full_page=True)
        figures = page.evaluate("""() => Array.from(document.querySelectorAll('figure')).map(f => {
            const els = Array.from(f.querySelectorAll('img, svg.main-svg, canvas'));
            return {id: f.id, n: els.length, sizes: els.map(e => {
                const r = e.getBoundingClientRect();
                const nat = e.tagName === 'IMG' ? [e.naturalWidth, e.naturalHeight] : [1, 1];
                return [e.tagName, r.width, r.height, nat[0], nat[1], e.complete !== false];
            })};
        })""")
        cells = page.evaluate("""() => Array.from(document.querySelectorAll(
            'td[data-value]')).map(td => ({
                table: td.closest('table').id,
                row: td.closest('tr').dataset.pallet ?? td.closest('tr').dataset.level ?? null,
                key: td.dataset.key, value: td.dataset.value, text: td.innerText}))""")
        ids = page.evaluate("""() => Array.from(document.querySelectorAll(
            '#table-pallets tbody tr td[data-key="id"]')).map(td => td.innerText)""")
        browser.close()
    summary = json.loads((d / "summary.json").read_text())
    return dict(errors=errors, figures=figures, cells=cells, ids=ids, summary=summary,
                shot=shot, html=html)


def test_no_console_errors(rendered):
    assert rendered["errors"] == [], f"screenshot: {rendered['shot']}"


def test_every_figure_rendered(rendered):
    figs = rendered["figures"]
    ids = {f["id"] for f in figs}
    want = {"fig-elevation", "fig-modes", "fig-record", "fig-spectrum", "fig-histories"}
    if rendered["summary"].get("dimension") == "3D":
        want.add("fig-plan")
    assert want <= ids, f"figures {ids}; screenshot: {rendered['shot']}"
    for f in figs:
        assert f["n"] > 0, f"figure {f['id']} has no image; screenshot: {rendered['shot']}"
        for tag, w, h, nw, nh, complete in f["sizes"]:
            assert w > 50 and h > 50 and nw > 0 and nh > 0 and complete, (
                f"figure {f['id']}: {tag} {w}x{h} (natural {nw}x{nh}) did not render; "
                f"screenshot: {rendered['shot']}")


def test_tables_hold_summary_json_numbers(rendered):
    s = rendered["summary"]
    shot = rendered["shot"]
    pallets = [c for c in rendered["cells"] if c["table"] == "table-pallets"]
    levels = [c for c in rendered["cells"] if c["table"] == "table-levels"]
    assert len(rendered["ids"]) == len(s["pallets"]), f"screenshot: {shot}"
    seen = 0
    for c in pallets:
        want = s["pallets"][int(c["row"])][c["key"]]
        assert json.loads(c["value"]) == want, f"pallet {c}; screenshot: {shot}"
        seen += 1
    assert seen >= 6 * len(s["pallets"]), f"screenshot: {shot}"
    for c in levels:
        want = s["peaks"]["per_level"][c["key"]][int(c["row"])]
        assert json.loads(c["value"]) == want, f"level {c}; screenshot: {shot}"
    # the shown text is the value in the header's unit: peak sliding in mm, 3 decimals
    for c in pallets:
        if c["key"] == "peak_sliding_m":
            want = s["pallets"][int(c["row"])]["peak_sliding_m"] * 1e3
            assert c["text"] == f"{want:.3f}", f"{c}; screenshot: {shot}"
    assert rendered["shot"].stat().st_size > 10_000
