"""The report's time text agrees with C++'s format_time_ns (tests/test_work_precision.cpp)."""
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from stepbench_report.formatting import fmt_count, fmt_time_ns  # noqa: E402


def test_a_time_is_rounded_before_its_unit_is_chosen():
    assert fmt_time_ns(999.7) == "1 us"
    assert fmt_time_ns(999.4) == "999 ns"
    assert fmt_time_ns(12345.0) == "12.3 us"
    assert fmt_time_ns(999_999.0) == "1 ms"
    assert fmt_time_ns(math.nan) == "n/a"


def test_a_count_is_rounded_before_its_unit_is_chosen():
    assert fmt_count(999_700) == "1M"
    assert fmt_count(12_345) == "12k"
    assert fmt_count(950) == "950"
