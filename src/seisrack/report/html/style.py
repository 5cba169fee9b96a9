"""Inline CSS of the HTML report (screen and A4 print)."""

CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, Arial, sans-serif;
       max-width: 1100px; margin: 0 auto; padding: 1em 2em; color: #222; line-height: 1.4; }
h1 { font-size: 1.6em; border-bottom: 2px solid #345; padding-bottom: .2em; }
h2 { font-size: 1.25em; color: #234; border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; margin: .8em 0; font-size: .85em; }
caption { caption-side: top; text-align: left; font-style: italic; padding: .3em 0; }
th, td { border: 1px solid #bbb; padding: .2em .5em; }
th { background: #eef2f6; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.risk td { background: #fde2e2; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; }
figcaption { font-size: .85em; font-style: italic; color: #444; }
.verdict-ok { color: #176317; font-weight: bold; }
.verdict-fail { color: #b00; font-weight: bold; }
.disagree { background: #fff3cd; border-left: 4px solid #e0a800; padding: .4em .8em; }
dl.inputs { display: grid; grid-template-columns: max-content auto; gap: .2em 1em; }
dl.inputs dt { font-weight: bold; }
.plot { width: 100%; min-height: 320px; }
@media print {
  @page { size: A4; margin: 14mm 12mm; }
  body { max-width: none; padding: 0; font-size: 10pt; }
  section { break-before: page; }
  section:first-of-type { break-before: auto; }
  figure, table { break-inside: avoid; }
  .plot { min-height: 0; }
  .screen-only { display: none; }
}
"""
