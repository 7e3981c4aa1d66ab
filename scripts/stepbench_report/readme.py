"""The README's answer block, rendered from the summary `stepbench summary` writes
(results/summary.json: per problem, the study's own frame-rate answers at 60 Hz, and its
equal-error verdict against the library peers at 1e-6 and finer). Nothing
here ranks, selects or computes: it formats the file's values (tests/python/test_readme.py
fails when README.md's block differs from this render of the committed summary)."""
import json
import math
import textwrap

from .verdict import cost_text, ratio_text, target_text, targets_span

# The README is a front page: no line of it over this many characters.
README_WIDTH = 160


class SummaryError(Exception):
    """A summary file that is missing, not JSON, or lacks what the block needs."""


def load(path):
    try:
        with open(path) as f:
            summary = json.load(f)
    except OSError as e:
        raise SummaryError(f"cannot read summary '{path}': {e.strerror} (`stepbench summary` writes it)") from None
    except json.JSONDecodeError as e:
        raise SummaryError(f"{path}:{e.lineno}:{e.colno}: not JSON: {e.msg}") from None
    try:
        for key in ("study", "hz", "targets", "problems"):
            summary[key]
        for p in summary["problems"]:
            for key in ("name", "unit", "scene", "answers", "stable_at_one_step", "methods_at_one_step"):
                p[key]
        for p in summary.get("against_peers", []):
            for key in ("name", "unit", "cells"):
                p[key]
            for c in p["cells"]:
                for key in ("target", "verdict", "cost_kind", "ratio", "noise_factor"):
                    c[key]
    except (KeyError, TypeError) as e:
        raise SummaryError(f"summary '{path}' lacks {e} (written by another version of `stepbench summary`?)") \
            from None
    return summary


def _answer_cell(answer, kind):
    if answer is None:
        return "-"
    if answer["method"] is None:
        return "none within 64 substeps"
    return f"{answer['method']} x{answer['substeps']}, {cost_text(kind, answer['cost_per_frame'])}"


# The README cell's short words for the verdicts (the study's words are in docs/results.md).
SHORT_VERDICT = {"within spread": "within"}


def _peer_cell(cell):
    """ours / peer, the verdict and the noise factor it was judged against (by time), or the
    one-sided verdict's word."""
    if cell is None:
        return "-"
    verdict = SHORT_VERDICT.get(cell["verdict"], cell["verdict"])
    if cell["ratio"] is None:
        return verdict
    if cell["cost_kind"] != "time_ns":
        by = "evaluations"
    else:  # none in a summary of a study written before the noise factor was stored
        by = f"noise {cell['noise_factor']:.3g}x" if cell["noise_factor"] is not None else ""
    return f"{ratio_text(cell['ratio'])} {verdict}" + (f" ({by})" if by else "")


def against_peers(summary):
    """The table against the fastest library peer at the tight targets, and what it means."""
    targets = summary.get("peer_targets", [])
    rows = summary.get("against_peers", [])
    if not targets or not rows:
        return []
    lines = ["| problem (unit) | " + " | ".join(f"ours / peer, {target_text(t)}" for t in targets) + " |",
             "|---|" + "---|" * len(targets)]
    for p in rows:
        cells = [f"{p['name']} ({p['unit']})"]
        cells += [_peer_cell(next((c for c in p["cells"] if math.isclose(c["target"], t, rel_tol=1e-9)), None))
                  for t in targets]
        lines.append("| " + " | ".join(cells) + " |")
    left_out = summary.get("against_peers_left_out", [])
    by = "measured time" if summary["study"]["cost_kind"] == "time_ns" else "counted force evaluations"
    prose = (f"At equal `err_pos_max`, {targets_span(targets)}: the cost of the fastest of our methods over the fastest library peer's "
             f"(below 1: ours cheaper), by {by}, each read off its measured curve. Ahead or behind only "
             "outside the noise factor b (1/b to b); within: inside it; bounded: undecided, the dearer side is charged "
             "an upper bound (its ladder does not bracket the target)."
             + (f" Left out, no peer reaching these targets there: {', '.join(left_out)}." if left_out else "")
             + " Which methods, and each ratio as force evaluations times time an evaluation: "
             "[docs/results.md](docs/results.md).")
    return [""] + lines + [""] + textwrap.wrap(prose, README_WIDTH - 10, break_long_words=False,
                                               break_on_hyphens=False)


def block(summary, command):
    """The table (per problem: at the summary's rate, the cheapest of our fixed-step methods
    and substeps a frame at each error, its cost a frame; how many stay stable at one step a
    frame), what it means, the table against the library peers at tight error (against_peers),
    the scenes as the study ran them, and the lines naming the study."""
    s, hz = summary["study"], summary["hz"]
    kind = s["cost_kind"]
    targets = summary["targets"]
    lines = ["| problem | " + " | ".join(f"{hz:g} Hz, error {target_text(t)}" for t in targets)
             + " | stable at one step a frame |",
             "|---|" + "---|" * (len(targets) + 1)]
    for p in summary["problems"]:
        by_target = {a["target"]: a for a in p["answers"]}
        cells = [f"{p['name']} ({p['unit']})"]
        cells += [_answer_cell(next((a for t, a in by_target.items() if math.isclose(t, target, rel_tol=1e-9)),
                                    None), kind) for target in targets]
        cells.append(f"{p['stable_at_one_step']} of {p['methods_at_one_step']}")
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    cost = ("the benchmark's median time a step of the method on the problem x the steps of a frame"
            if kind == "time_ns" else "its force evaluations (an untimed study)")
    prose = [f"At {hz:g} frames a second and an error: the cheapest of our fixed-step methods with n substeps a "
             f"frame (x n) whose `err_pos_max` (the worst body's largest position error, measured at the frame "
             f"ends against the truth, in the problem's unit) stays within it, and its cost a frame: {cost}. "
             "`stepbench advise --problem P --hz H --tol X` gives the same answer and runs any other rate or "
             "scene (`--set`).",
             "The scenes as the study ran them (`stepbench list` says what each parameter is): "
             + "; ".join(f"`{p['name']}`: {p['scene']}" for p in summary["problems"]) + "."]
    lines += [""] + textwrap.wrap(prose[0], README_WIDTH - 10, break_long_words=False, break_on_hyphens=False)
    lines += against_peers(summary)
    lines += [""] + textwrap.wrap(prose[1], README_WIDTH - 10, break_long_words=False, break_on_hyphens=False)
    lines += ["", "Every target against the library peers, the findings, the pendulum challenge and the scans' "
              "range answers:", "[docs/results.md](docs/results.md), written from the same study.",
              "", f"Study `{s['path']}`, commit {s['git_commit']}, {s['cpu']}, {s['created_utc']}; summary by "
              "`stepbench summary`,", f"block by `{command}`."]
    return "\n".join(lines)
