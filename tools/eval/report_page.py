#!/usr/bin/python3
"""The per-run report's HTML page (sss-report's index.html).

Reads PAGE_DATA/page.json, which sss-report writes (tools/eval/run_report_render.cpp: title,
verdict, key table, notes, sections with their figures and tables, metric tables, inputs), and
writes OUT_DIR/index.html: one self-contained file (inline CSS, no script, nothing fetched), with
the figures that report_figures.py drew beside it. Standard library only, so a machine without
matplotlib still gets the page. report.md carries the same content as Markdown.

Exit codes: 0 written; 2 bad arguments or an unreadable page.json; 1 index.html not writable.
"""

import argparse
import json
import os
import sys

CSS = (
    "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;max-width:1240px;margin:1.5em auto;"
    "padding:0 1em;color:#222;line-height:1.4}\n"
    "h1{font-size:1.5em;margin-bottom:.3em}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #ddd}\n"
    ".verdict{font-size:1.15em;padding:.7em 1em;border-left:6px solid #888;background:#f4f4f4}\n"
    ".verdict.better{border-color:#2a9d2a;background:#eaf6ea}.verdict.worse{border-color:#c62828;background:#fbeaea}\n"
    "table{border-collapse:collapse;margin:.6em 0 1.2em}caption{text-align:left;font-weight:600;padding:.3em 0}\n"
    "th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}th[scope=row]{text-align:left;font-weight:normal}\n"
    "tr:first-child th{background:#f0f0f0}td.good{background:#dff2df}td.bad{background:#f8dcdc}\n"
    "figure{margin:.5em 0 1.2em}figure img{max-width:100%;border:1px solid #ccc}figcaption{color:#555;font-size:.92em}\n"
    ".row{display:flex;gap:1em;flex-wrap:wrap}.row figure{flex:1 1 45%}\n"
    ".notes{background:#fff8e1;border:1px solid #f0d890;padding:.5em 1em}.small{color:#666;font-size:.9em}\n"
)

METRICS_NOTE = (
    "improvement = (DR - SLAM) / DR; green: SLAM better, red: SLAM worse. ATE: absolute trajectory error "
    "against the truth at the same time stamps; SE(3)-aligned: after the best rigid alignment of the whole "
    "trajectory; gauge-free: after the best horizontal rotation and scale about the estimate's first position, "
    "without a shift (what a constant heading bias and a DVL scale factor do, which no loop closure sees). "
    "RPE: relative pose error over the given path length."
)


def escape(text):
    """&, <, > and the double quote (attributes are double-quoted)."""
    return (str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;"))


def html_table(table):
    """A table: header row, then rows whose first cell heads the row; tone +1 green, -1 red."""
    out = ["<table>\n"]
    if table["caption"]:
        out.append(f"<caption>{escape(table['caption'])}</caption>\n")
    out.append("<tr>" + "".join(f"<th>{escape(h)}</th>" for h in table["header"]) + "</tr>\n")
    for row in table["rows"]:
        out.append("<tr>")
        for c, cell in enumerate(row):
            tone = ' class="good"' if cell["tone"] > 0 else ' class="bad"' if cell["tone"] < 0 else ""
            span = f' colspan="{cell["span"]}" style="text-align:left"' if cell["span"] > 1 else ""
            if c == 0:
                out.append(f'<th scope="row"{tone}{span}>{escape(cell["text"])}</th>')
            else:
                out.append(f"<td{tone}{span}>{escape(cell['text'])}</td>")
        out.append("</tr>\n")
    out.append("</table>\n")
    return "".join(out)


def html_figures(figures):
    """Figures in order; consecutive ones of the same non-empty group side by side."""
    out = []
    for i, figure in enumerate(figures):
        group = figure["group"]
        starts = group and (i == 0 or figures[i - 1]["group"] != group)
        ends = group and (i + 1 == len(figures) or figures[i + 1]["group"] != group)
        if starts:
            out.append('<div class="row">\n')
        out.append(f'<figure><img src="{escape(figure["file"])}" alt="{escape(figure["alt"])}">'
                   f'<figcaption>{escape(figure["caption"])}</figcaption></figure>\n')
        if ends:
            out.append("</div>\n")
    return "".join(out)


def render(page):
    out = ['<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n',
           f"<title>{escape(page['title'])}</title>\n<style>\n{CSS}</style>\n</head>\n<body>\n",
           f"<h1>{escape(page['title'])}</h1>\n",
           f'<p class="small">mission {escape(page["mission_dir"])} &middot; run {escape(page["run_dir"])}</p>\n',
           f'<p class="verdict {escape(page["outcome"])}">{escape(page["verdict"])}</p>\n',
           html_table(page["key"])]
    if page["notes"]:
        out.append('<div class="notes"><strong>Notes</strong> (missing or unusable inputs; their sections are left '
                   "out)\n<ul>\n")
        out.extend(f"<li>{escape(note)}</li>\n" for note in page["notes"])
        out.append("</ul></div>\n")
    for section in page["sections"]:
        out.append(f"<h2>{escape(section['heading'])}</h2>\n")
        if section["text"]:
            out.append(f"<p>{escape(section['text'])}</p>\n")
        out.append(html_figures(section["figures"]))
        out.extend(html_table(table) for table in section["tables"])
    out.append("<h2>7. Metrics</h2>\n")
    out.append(f'<p class="small">{escape(METRICS_NOTE)}</p>\n')
    out.extend(html_table(table) for table in page["metric_tables"])
    out.append('<h2>Inputs</h2>\n<ul class="small">\n')
    out.extend(f"<li>{escape(path)}</li>\n" for path in page["inputs"])
    out.append('</ul>\n<p class="small">Written by sss-report (machine-readable: <a href="metrics.json">'
               "metrics.json</a>).</p>\n</body>\n</html>\n")
    return "".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page_data", help="folder with page.json")
    parser.add_argument("out_dir", help="folder of index.html and its figures")
    args = parser.parse_args()
    path = os.path.join(args.page_data, "page.json")
    try:
        with open(path, encoding="utf-8") as file:
            page = json.load(file)
        html = render(page)
    except (OSError, ValueError, KeyError, TypeError) as error:
        print(f"report_page.py: {path}: {error!r}; rerun sss-report, which writes it", file=sys.stderr)
        return 2
    out_path = os.path.join(args.out_dir, "index.html")
    try:
        with open(out_path, "w", encoding="utf-8") as file:
            file.write(html)
    except OSError as error:
        print(f"report_page.py: cannot write {out_path}: {error.strerror}; check the folder is writable",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
