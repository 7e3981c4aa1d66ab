"""A small document model written out twice: REPORT.md and a self-contained index.html
(inline CSS, images beside it in fig/, no network)."""
import html
import re


class Doc:
    def __init__(self, title):
        self.title = title
        self.blocks = []

    def h(self, level, text, anchor=None):
        self.blocks.append(("h", level, text, anchor or slug(text)))

    def p(self, text):
        self.blocks.append(("p", text))

    def note(self, text):
        self.blocks.append(("note", text))

    def table(self, headers, rows, caption=None):
        self.blocks.append(("table", headers, [[("" if c is None else str(c)) for c in r] for r in rows], caption))

    def img(self, src, alt, caption=None):
        self.blocks.append(("img", src, alt, caption))

    def pre(self, text):
        self.blocks.append(("pre", text))

    def toc(self):
        return [(b[1], b[2], b[3]) for b in self.blocks if b[0] == "h" and b[1] == 2]


def slug(text):
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")


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
        elif kind == "pre":
            out += ["```", b[1], "```", ""]
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
            _, src, alt, caption = b
            out += [f"![{alt}]({src})", ""]
            if caption:
                out += [f"*{caption}*", ""]
    return "\n".join(out).rstrip() + "\n"


def _inline(text):
    """Escape, then `code` spans."""
    t = html.escape(text)
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", t)


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
td.n { white-space: nowrap; }
img { max-width: 100%; border: 1px solid #e4e4e4; }
figure { margin: 0.8em 0 1.6em; }
figcaption { font-size: 0.88em; color: #555; }
.note { background: #fff8e1; border-left: 4px solid #f0b400; padding: 0.4em 0.8em; }
.caption { font-size: 0.9em; color: #444; margin-bottom: 0.2em; }
nav ul { columns: 2; font-size: 0.95em; }
code, pre { font-family: "DejaVu Sans Mono", monospace; font-size: 0.92em; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; }
"""


def to_html(doc):
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>{html.escape(doc.title)}</title>", f"<style>{CSS}</style></head><body>",
           f"<h1>{html.escape(doc.title)}</h1>"]
    toc = doc.toc()
    if toc:
        out.append("<nav><ul>" + "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for _, t, a in toc)
                   + "</ul></nav>")
    for b in doc.blocks:
        kind = b[0]
        if kind == "h":
            out.append(f'<h{b[1]} id="{b[3]}">{html.escape(b[2])}</h{b[1]}>')
        elif kind == "p":
            out.append(f"<p>{_inline(b[1])}</p>")
        elif kind == "note":
            out.append(f'<p class="note">{_inline(b[1])}</p>')
        elif kind == "pre":
            out.append(f"<pre>{html.escape(b[1])}</pre>")
        elif kind == "table":
            _, headers, rows, caption = b
            if caption:
                out.append(f'<p class="caption">{_inline(caption)}</p>')
            out.append("<table><thead><tr>" + "".join(f"<th>{_inline(h)}</th>" for h in headers) + "</tr></thead><tbody>")
            for r in rows:
                # Short cells (numbers, dt values, names) do not wrap; prose does.
                out.append("<tr>" + "".join(f'<td class="n">{_inline(c)}</td>' if len(c) <= 28 else
                                            f"<td>{_inline(c)}</td>" for c in r) + "</tr>")
            out.append("</tbody></table>")
        elif kind == "img":
            _, src, alt, caption = b
            cap = f"<figcaption>{_inline(caption)}</figcaption>" if caption else ""
            out.append(f'<figure><img src="{html.escape(src)}" alt="{html.escape(alt)}">{cap}</figure>')
    out.append("</body></html>")
    return "\n".join(out) + "\n"
