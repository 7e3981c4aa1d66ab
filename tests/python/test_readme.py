"""The README is a front page from the study it ships (issue 32): its answer block is the
render of the committed results/summary.json (`stepbench summary` of the study it names,
scripts/report --readme), it is at most 160 lines, none over 160 characters, and its
opening answers before it instructs."""
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from stepbench_report import readme, verdict  # noqa: E402


def block_of(text):
    start, end = text.index(verdict.BEGIN), text.index(verdict.END)
    return text[start + len(verdict.BEGIN):end].strip("\n")


def test_the_block_is_the_render_of_the_committed_summary():
    summary = readme.load(ROOT / "results" / "summary.json")
    block = block_of((ROOT / "README.md").read_text())
    # The command that wrote the block is its last line, quoted; the rest is the summary's.
    last = block.splitlines()[-1]
    assert last.startswith("block by `scripts/report ") and last.endswith("`."), last
    command = last[len("block by `"):-len("`.")]
    assert "--readme README.md" in command, command
    assert block == readme.block(summary, command)


def test_the_summary_answers_every_problem_at_1e_3():
    summary = readme.load(ROOT / "results" / "summary.json")
    assert summary["hz"] == 60 and 1e-3 in summary["targets"]
    assert summary["study"]["path"] == "results/study.h5" and summary["study"]["timed"] is True
    for p in summary["problems"]:
        answers = {a["target"]: a for a in p["answers"]}
        assert 1e-3 in answers, p["name"]
        a = answers[1e-3]
        # An answer meets its target, at a positive cost; "none" carries no method.
        assert a["method"] is None or (0 < a["err_pos_max"] <= 1e-3 and a["cost_per_frame"] > 0), (p["name"], a)
    rope = next(p for p in summary["problems"] if p["name"] == "spring_chain")
    assert rope["scene"].startswith("masses = 32, "), rope["scene"]


def test_the_summary_sets_ours_against_the_peers_at_tight_error():
    """The five smooth problems of the equal-error goal, at each of 1e-6 .. 1e-12: both sides
    reach it, ranked by measured time, judged against a noise factor of at least 1.15 (the
    rule's floor), the ratio the product of its two factors (evaluations at equal error, time
    an evaluation); the contact scenes, where no library peer runs, left out by name."""
    summary = readme.load(ROOT / "results" / "summary.json")
    assert summary["peer_targets"] == [1e-6, 1e-8, 1e-10, 1e-12]
    rows = {p["name"]: p for p in summary["against_peers"]}
    for name in ("damped_spring", "pendulum", "n_pendulum", "kepler", "spring_chain"):
        cells = rows[name]["cells"]
        assert [c["target"] for c in cells] == summary["peer_targets"], name
        for c in cells:
            assert c["ours"] and c["peer"] and c["cost_kind"] == "time_ns" and c["noise_factor"] >= 1.15, (name, c)
            assert abs(c["evals_ratio"] * c["per_eval_ratio"] / c["ratio"] - 1) < 1e-12, (name, c)
            ahead, behind = c["ratio"] < 1 / c["noise_factor"], c["ratio"] > c["noise_factor"]
            assert c["verdict"] in (("ahead",) if ahead else ("behind",) if behind else ("within spread",)) + (
                "bounded",), (name, c)
    assert "bouncing_balls" in summary["against_peers_left_out"]


def test_the_readme_is_a_front_page():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 160, len(lines)
    long = [(i + 1, len(line)) for i, line in enumerate(lines) if len(line) > 160]
    assert not long, long
    # The answer table opens it, before the commands that set it up.
    text = "\n".join(lines)
    assert text.index("| problem | 60 Hz, error 1e-2 |") < text.index("## Two commands")
