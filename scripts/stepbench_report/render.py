"""A small document model written out as Markdown (REPORT.md, --markdown, --readme)
and as a small site through python3-markdown (inline CSS, images beside it in fig/ or
inlined, no network): what comes before the first page() is index.html, each page() a
page of its own (REPORT.md is the whole document, in the same order). A table whose
cells carry their own HTML (Cell) or a class is written into the HTML as an HTML table
(python3-markdown passes a raw HTML block through as it is), and into the Markdown as a
Markdown table of the cells' text."""
import base64
import html
import os
import re
from dataclasses import dataclass

import markdown as md_lib


@dataclass(frozen=True)
class Cell:
    """A table cell with a Markdown text and an HTML form (already escaped), and a CSS class."""
    md: str
    html: str
    cls: str = ""


def esc(text):
    return html.escape(str(text), quote=True)


class Doc:
    def __init__(self, title):
        self.title = title
        self.blocks = []

    def h(self, level, text):
        self.blocks.append(("h", level, text))

    def p(self, text, cls=None):
        """A paragraph; `cls`: its class in index.html (then only `code` spans are marked up)."""
        self.blocks.append(("p", text, cls))

    def note(self, text):
        self.blocks.append(("note", text))

    def pre(self, text):
        """Text as printed by stepbench, kept line for line (a fenced block in Markdown)."""
        self.blocks.append(("pre", str(text).rstrip("\n")))

    def items(self, lines):
        """A bullet list."""
        self.blocks.append(("items", [str(x) for x in lines]))

    def table(self, headers, rows, caption=None, cls=None):
        """`cls`: the HTML table's class (written as an HTML table); a row's cells are
        text or Cell."""
        cells = [[c if isinstance(c, Cell) else ("" if c is None else str(c)) for c in r] for r in rows]
        self.blocks.append(("table", headers, cells, caption, cls))

    def img(self, src, alt):
        self.blocks.append(("img", src, alt))

    def fold(self, summary):
        """What follows, up to unfold(), folded in index.html under `summary` (a <details>
        element, closed); REPORT.md shows it as it is."""
        self.blocks.append(("fold", summary))

    def unfold(self):
        self.blocks.append(("unfold",))

    def toc(self):
        """Where the contents go in index.html (REPORT.md has none: its viewer lists the headings)."""
        self.blocks.append(("toc",))

    def page(self, path, title=None):
        """What follows, up to the next page(), is the page `path` of the site (relative to
        its folder: `problems/pendulum.html`), titled `title` or, without one, by its first
        second-level heading (which the page shows as its title). REPORT.md runs on."""
        self.blocks.append(("page", path, title))

    def pages(self):
        """[(path, Doc)]: index.html (what comes before the first page()), then each page."""
        out = [("index.html", Doc(self.title))]
        for b in self.blocks:
            if b[0] == "page":
                out.append((b[1], Doc(b[2])))
            elif out[-1][1].title is None and b[0] == "h" and b[1] == 2:
                out[-1][1].title = b[2]
            else:
                out[-1][1].blocks.append(b)
        return out


def _inline(text):
    """Markdown's `code` spans in escaped text, for a paragraph written as HTML."""
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", esc(text))


def _md_cell(cell):
    text = cell.md if isinstance(cell, Cell) else cell
    return text.replace("|", "\\|").replace("\n", " ")


def _html_table(headers, rows, cls):
    out = [f'<table class="{esc(cls)}">' if cls else "<table>", "<thead><tr>"]
    out += [f"<th>{esc(h)}</th>" for h in headers]
    out.append("</tr></thead><tbody>")
    for r in rows:
        out.append("<tr>")
        for c in r:
            if isinstance(c, Cell):
                out.append(f'<td class="{esc(c.cls)}">{c.html}</td>' if c.cls else f"<td>{c.html}</td>")
            else:
                out.append(f"<td>{esc(c)}</td>")
        out.append("</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def markdown(doc, for_html=False):
    """The document as Markdown; `for_html`: the text index.html is converted from (rich
    tables as HTML, the contents' marker)."""
    out = [f"# {doc.title}", ""]
    for b in doc.blocks:
        kind = b[0]
        if kind == "h":
            out += ["#" * b[1] + " " + b[2], ""]
        elif kind == "p":
            _, text, cls = b
            out += [f'<p class="{esc(cls)}">{_inline(text)}</p>' if for_html and cls else text, ""]
        elif kind == "note":
            out += ["> " + b[1], ""]
        elif kind == "items":
            out += [f"- {line}" for line in b[1]] + [""]
        elif kind == "pre":
            out += ([f"<pre>{esc(b[1])}</pre>"] if for_html else ["```", b[1], "```"]) + [""]
        elif kind == "table":
            _, headers, rows, caption, cls = b
            if caption:
                out += [caption, ""]
            if for_html and (cls or any(isinstance(c, Cell) for r in rows for c in r)):
                out += [_html_table(headers, rows, cls), ""]
                continue
            out.append("| " + " | ".join(_md_cell(h) for h in headers) + " |")
            out.append("|" + "|".join("---" for _ in headers) + "|")
            for r in rows:
                out.append("| " + " | ".join(_md_cell(c) for c in r) + " |")
            out.append("")
        elif kind == "img":
            _, src, alt = b
            out += [f"![{alt}]({src})", ""]
        elif kind == "toc" and for_html:
            out += ["[TOC]", ""]
        elif kind == "fold" and for_html:  # md_in_html: Markdown inside the element is converted
            out += ['<details markdown="1">', f"<summary>{esc(b[1])}</summary>", ""]
        elif kind == "unfold" and for_html:
            out += ["</details>", ""]
    return "\n".join(out).rstrip() + "\n"


CSS = """
body { font-family: -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; margin: 0 auto;
       max-width: 1320px; padding: 0.5em 1.4em 4em; color: #1d1d1f; line-height: 1.45; }
h1 { font-size: 1.4em; margin: 0.2em 0 0.1em; }
h1 + p { margin: 0 0 0.3em; color: #555; font-size: 0.88em; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.15em; margin-top: 1.8em; font-size: 1.3em; }
h1 + p + h2 { margin-top: 0.4em; font-size: 1.1em; }
h1 + h2 { margin-top: 0.5em; }
h3 { margin-top: 1.5em; font-size: 1.1em; }
p, ul, blockquote { max-width: 78em; }
table { border-collapse: collapse; margin: 0.5em 0 1.1em; font-size: 0.88em; max-width: 100%; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: left; vertical-align: top;
         overflow-wrap: anywhere; }
th { background: #f2f2f2; }
tr:nth-child(even) td { background: #fafafa; }
td { font-variant-numeric: tabular-nums; }
table.verdict, table.frames { width: 100%; table-layout: fixed; font-size: 12px; line-height: 1.3;
                               margin: 0.3em 0; }
table.verdict th:first-child, table.frames th:first-child { width: 11.5em; }
table.verdict td, table.frames td { padding: 0.15em 0.35em; }
table.answer { width: 100%; table-layout: fixed; font-size: 13px; line-height: 1.3; margin: 0.3em 0 0.6em; }
table.answer th:first-child { width: 34%; }
table.answer th:last-child { width: 14%; }
table.answer td { padding: 0.2em 0.4em; }
table.answer td:last-child, table.answer .small { font-size: 11px; }
table.answer td.none { color: #999; }
p.lead { margin: 0.3em 0 0.2em; }
p.nav { margin: 0.6em 0 0; font-size: 0.88em; }
table.verdict td.ahead { background: #e4f3e0; }
table.verdict td.behind { background: #fbe4e1; }
table.verdict td.within { background: #efefef; color: #555; }
table.verdict td.none, table.frames td.none { color: #999; }
.small { color: #666; font-size: 0.92em; }
.caption { font-size: 0.82em; color: #555; margin: 0 0 0.6em; }
img { max-width: 100%; height: auto; border: 1px solid #e4e4e4; margin: 0.6em 0 1.2em; }
blockquote { background: #fff8e1; border-left: 4px solid #f0b400; padding: 0.4em 0.8em; margin: 1em 0; }
blockquote p { margin: 0; }
.toc ul { columns: 3; font-size: 0.92em; }
details { margin: 0.3em 0 0.8em; }
summary { cursor: pointer; color: #0b57a4; font-size: 0.92em; }
.toc .toctitle { font-weight: bold; }
code { font-family: "DejaVu Sans Mono", monospace; font-size: 0.92em; }
"""


def _from_folder(body, depth):
    """The page's links and images, written relative to the site's folder, relative to a
    page `depth` folders down."""
    if not depth:
        return body
    up = "../" * depth
    return re.sub(r'(href|src)="(?![a-z]+:|#|/)', lambda m: f'{m.group(1)}="{up}', body)


def site(doc, figdir=None):
    """{path: HTML} of every page of `doc` (Doc.pages), each with a line back to the index."""
    out = {}
    for path, page in doc.pages():
        depth = path.count("/")
        nav = "" if path == "index.html" else f'<p class="nav"><a href="index.html">{esc(doc.title)}</a></p>'
        out[path] = to_html(page, figdir, depth=depth, nav=nav)
    return out


def to_html(doc, figdir=None, depth=0, nav=""):
    """A page: the document converted by python3-markdown (its tables, its toc extension
    for the heading ids and the contents, second-level headings, and md_in_html for the
    folded parts). `figdir`: the folder holding the figures, to inline each as a data: URI;
    `depth`: how many folders down the page lies (its links are written from the top);
    `nav`: HTML above the title."""
    converter = md_lib.Markdown(extensions=["tables", "toc", "md_in_html"],
                                extension_configs={"toc": {"toc_depth": "2-2", "title": "Contents"}})
    body = converter.convert(markdown(doc, for_html=True))
    if figdir is not None:
        def inline(m):
            with open(os.path.join(figdir, os.path.basename(m.group(1))), "rb") as f:
                return 'src="data:image/png;base64,' + base64.b64encode(f.read()).decode("ascii") + '"'
        body = re.sub(r'src="(fig/[^"]+\.png)"', inline, body)
    return "\n".join(["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
                      '<meta name="viewport" content="width=device-width, initial-scale=1">',
                      f"<title>{html.escape(doc.title)}</title>", f"<style>{CSS}</style></head><body>",
                      _from_folder(nav + body, depth), "</body></html>"]) + "\n"
