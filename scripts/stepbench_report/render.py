"""A small document model written out as REPORT.md, and REPORT.md turned into a
self-contained index.html by python3-markdown (inline CSS, images beside it in fig/,
no network)."""
import html

import markdown as md_lib


class Doc:
    def __init__(self, title):
        self.title = title
        self.blocks = []

    def h(self, level, text):
        self.blocks.append(("h", level, text))

    def p(self, text):
        self.blocks.append(("p", text))

    def note(self, text):
        self.blocks.append(("note", text))

    def table(self, headers, rows, caption=None):
        self.blocks.append(("table", headers, [[("" if c is None else str(c)) for c in r] for r in rows], caption))

    def img(self, src, alt):
        self.blocks.append(("img", src, alt))


def _md_cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def markdown(doc):
    out = [f"# {doc.title}", ""]
    for b in doc.blocks:
        kind = b[0]
        if kind == "h":
            out += ["#" * b[1] + " " + b[2], ""]
        elif kind == "p":
            out += [b[1], ""]
        elif kind == "note":
            out += ["> " + b[1], ""]
        elif kind == "table":
            _, headers, rows, caption = b
            if caption:
                out += [caption, ""]
            out.append("| " + " | ".join(_md_cell(h) for h in headers) + " |")
            out.append("|" + "|".join("---" for _ in headers) + "|")
            for r in rows:
                out.append("| " + " | ".join(_md_cell(c) for c in r) + " |")
            out.append("")
        elif kind == "img":
            _, src, alt = b
            out += [f"![{alt}]({src})", ""]
    return "\n".join(out).rstrip() + "\n"


CSS = """
body { font-family: -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; margin: 0 auto;
       max-width: 1180px; padding: 1.2em 1.6em 4em; color: #1d1d1f; line-height: 1.45; }
h1 { font-size: 1.7em; margin-bottom: 0.2em; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2em; margin-top: 2em; }
h3 { margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
tr:nth-child(even) td { background: #fafafa; }
td { font-variant-numeric: tabular-nums; }
img { max-width: 100%; border: 1px solid #e4e4e4; margin: 0.8em 0 1.6em; }
blockquote { background: #fff8e1; border-left: 4px solid #f0b400; padding: 0.4em 0.8em; margin: 1em 0; }
blockquote p { margin: 0; }
.toc ul { columns: 2; font-size: 0.95em; }
code { font-family: "DejaVu Sans Mono", monospace; font-size: 0.92em; }
"""


def to_html(markdown_text, title):
    """index.html from REPORT.md: python3-markdown's tables, and its toc extension for
    the heading ids and the contents (second-level headings) at the top."""
    converter = md_lib.Markdown(extensions=["tables", "toc"], extension_configs={"toc": {"toc_depth": "2-2"}})
    body = converter.convert(markdown_text)
    # The contents go right under the title.
    body = body.replace("</h1>", f'</h1>\n<nav class="toc">{converter.toc}</nav>', 1)
    return "\n".join(["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
                      f"<title>{html.escape(title)}</title>", f"<style>{CSS}</style></head><body>",
                      body, "</body></html>"]) + "\n"
