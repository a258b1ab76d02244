"""The page's HTML skeleton and style sheet (inline; no font, icon or
script is loaded from anywhere). The favicon is an empty data URI so the
browser requests nothing when the page is opened from disk."""

from __future__ import annotations

STYLE = """
:root { --ok: #1e8449; --bad: #c0392b; --muted: #6b6b6b; --line: #d5d5d5; --hi: #fff3c4; }
* { box-sizing: border-box; }
body { font: 13px/1.4 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 0; color: #1d1d1d; }
header { padding: 8px 14px; border-bottom: 1px solid var(--line); background: #fafafa; }
header h1 { font-size: 17px; margin: 0 0 2px 0; }
header p { margin: 2px 0; color: var(--muted); }
a { color: #1f5fa8; }
.notice { background: var(--hi); padding: 4px 8px; margin: 4px 0; border-radius: 3px; color: #333; }
#index-view, #episode-view { padding: 8px 14px; }
#filters { display: flex; flex-wrap: wrap; gap: 6px 16px; align-items: center; margin-bottom: 8px; }
#filters label { white-space: nowrap; }
#count { color: var(--muted); }
table.index { border-collapse: collapse; font-size: 12px; }
table.index th, table.index td { border-bottom: 1px solid #eee; padding: 2px 5px; text-align: left; white-space: nowrap; }
table.index th { position: sticky; background: #f3f3f3; cursor: pointer; user-select: none; }
table.index thead tr:first-child th { top: 0; }
table.index thead tr:nth-child(2) th { top: 21px; }
table.index th.group { text-align: center; border-left: 2px solid #ccc; cursor: default; }
table.index td.first { border-left: 2px solid #ccc; }
table.index th.sorted::after { content: " \\25B4"; }
table.index th.sorted.desc::after { content: " \\25BE"; }
table.index tbody tr:hover { background: #f5f9ff; }
table.index td.run { cursor: pointer; }
.dot { display: inline-block; width: 9px; height: 9px; border-radius: 50%; margin-right: 2px; }
.dot.ok { background: var(--ok); } .dot.bad { background: var(--bad); }
.easy { color: #1e8449; } .medium { color: #b9770e; } .hard { color: #c0392b; }
#episode-head h2 { font-size: 15px; margin: 4px 0; }
#episode-head .facts { color: #333; margin: 2px 0; }
#episode-head .nav { display: flex; gap: 10px; align-items: center; margin: 6px 0; flex-wrap: wrap; }
#panels { display: flex; gap: 14px; align-items: flex-start; flex-wrap: wrap; }
.panel { flex: 1 1 520px; min-width: 420px; border: 1px solid var(--line); border-radius: 4px; padding: 8px; }
.panel h3 { font-size: 14px; margin: 0 0 4px 0; }
.panel svg.map { width: 100%; height: 430px; background: #fff; border: 1px solid #eee; }
.controls { display: flex; gap: 6px; align-items: center; margin: 6px 0; }
.controls input[type=range] { flex: 1; }
.step-label { min-width: 120px; text-align: right; color: var(--muted); }
.detail { background: #fbfbfb; border: 1px solid #eee; padding: 6px 8px; min-height: 60px; }
.detail p { margin: 3px 0; }
.detail .decision { font-weight: 600; }
.detail .oracle { color: #4a235a; }
.detail ul { margin: 2px 0 2px 18px; padding: 0; }
.detail .muted { color: var(--muted); }
.images { display: flex; gap: 8px; flex-wrap: wrap; margin: 4px 0; }
.images figure { margin: 0; }
.images figcaption { color: var(--muted); font-size: 11px; }
.images img { max-width: 100%; max-height: 260px; display: block; }
.grounder { position: relative; display: inline-block; }
.grounder .cell { position: absolute; border: 2px solid #ff1744; background: rgba(255, 23, 68, 0.18); }
.call { border-top: 1px dashed #ccc; margin-top: 4px; padding-top: 4px; }
.call pre { white-space: pre-wrap; word-break: break-word; max-height: 240px; overflow: auto; background: #f4f4f4;
            margin: 2px 0; padding: 4px; font-size: 11px; }
.call .error { color: var(--bad); }
ol.step-list { margin: 6px 0 0 0; padding-left: 28px; max-height: 260px; overflow: auto; font-size: 12px; }
ol.step-list li { cursor: pointer; padding: 1px 2px; }
ol.step-list li.current { background: var(--hi); }
ol.step-list li.ask { color: #6c3483; } ol.step-list li.stop { font-weight: 600; }
.legend { color: var(--muted); font-size: 11px; margin-top: 2px; }
.legend span { margin-right: 10px; }
.sw { display: inline-block; width: 10px; height: 10px; vertical-align: middle; margin-right: 3px; border: 1px solid #555; }
"""


def page_html(title: str, style: str, script: str, data: str) -> str:
    """The page's HTML from its parts (each inserted verbatim; ``title`` already escaped)."""
    return "".join([
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n',
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n',
        '<link rel="icon" href="data:,">\n<title>', title, "</title>\n<style>", style, "</style>\n</head>\n<body>\n",
        '<header><h1 id="title"></h1><p id="summary"></p><div id="notices"></div></header>\n',
        '<section id="index-view"><div id="filters"></div>'
        '<table class="index" id="index"><thead></thead><tbody></tbody></table></section>\n',
        '<section id="episode-view" hidden><div id="episode-head"></div><div id="panels"></div></section>\n',
        '<script type="application/json" id="ignjax-data">', data, "</script>\n",
        "<script>", script, "</script>\n</body>\n</html>\n",
    ])


__all__ = ["STYLE", "page_html"]
