"""The study file's schema as the C++ side declares it (store/schema.hpp): schema.json
beside this file is what `stepbench schema` prints, and a test (ctest schema_python_copy)
fails when the two differ. Every reader of the package takes its fields, the format
version, the "row completed" rule and what `param` holds from here. A leaf module: it
imports nothing of the package."""
import json
import os

import numpy as np

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "schema.json")) as _f:
    SCHEMA = json.load(_f)

FORMAT_VERSION = SCHEMA["format_version"]  # the only format_version the report reads
PARAM_KIND = SCHEMA["param_kind"]  # method kind -> what `param` holds
PARAMETER_KINDS = tuple(SCHEMA["parameter_kinds"])


def fields(table, timed=False):
    """The fields of a table in order, with its timed-only groups when `timed`."""
    return tuple(name for g in SCHEMA["tables"][table]["groups"] if timed or not g["timed_only"]
                 for name, _ in g["fields"])


def timed_fields(table):
    """The fields present only in a timed study."""
    return tuple(name for g in SCHEMA["tables"][table]["groups"] if g["timed_only"] for name, _ in g["fields"])


def completed(rows):
    """The rows that completed: none of the schema's incomplete flags set (core/measure.hpp's
    row_completed)."""
    flags = SCHEMA["row_incomplete_flags"]
    return np.logical_and.reduce([np.asarray(rows[f]) == 0 for f in flags])
