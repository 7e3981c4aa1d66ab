"""stepbench's report generator: a study file in, REPORT.md + index.html + fig/*.png out.
Entry point: scripts/report (see cli.main)."""
