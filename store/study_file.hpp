#pragma once
// The study file (HDF5): the public format users script against. Layout documented in
// docs/study-format.md; bump study_format_version when it changes incompatibly.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/work_precision.hpp"
#include "store/columns.hpp"
#include "store/h5.hpp"
#include "study/study.hpp"

namespace stepbench {

inline constexpr int study_format_version = schema::format_version;

// Throws std::runtime_error ("cannot write results file '<path>': <reason>") when the
// path cannot be created; leaves nothing behind. Call before a long run.
void check_writable(const std::string& path);

// Builds a study file in memory with `fill` and writes it to a temporary file beside
// `path`, renamed into place when whole: an existing file is replaced whole or not at all
// (parts/study.hpp write_study fills it with the root attributes and every part; a merge
// with the shards). An HDF5 error is "<failing> '<path>': HDF5: <error>"; `before_write`,
// if given, runs between the build and the write.
void write_study_file(const std::string& path, const std::function<void(H5::H5File&)>& fill,
                      std::string_view failing = "cannot write results file",
                      const std::function<void()>& before_write = {});

// The root attributes of a study file: format, build, machine, the sweep's settings
// (`described_options`: the parts' describe lines), timing.
void write_root_attributes(H5::H5File& file, const study& s, const std::string& described_options);

// /problems: the sweep's rows, each problem's truth, references, equal-error table and
// fronts.
void write_problems(H5::Group& root, const study& s);

// /problems read back (the sweep's read): each problem's facts, truth outcome and scales
// (not its states), the references' outcomes and every method (info, fit, rows), in the
// file's order of names.
void read_problems(const H5::Group& root, study& s);

// The machine a study ran on (run/machine.hpp), as attributes of `obj`: cpu, cores,
// and with timings num_cpus, mhz_per_cpu, cpu_scaling_enabled (Google Benchmark's context).
void write_machine(H5::H5Object& obj, const std::optional<timing_settings>& timing);

// Writes `size` bytes from `data` to the descriptor whole, again when interrupted: 0, or
// the errno of the write that failed (EIO for one that wrote nothing).
int write_bytes(int fd, const void* data, std::size_t size);

// An image of a file written to a temporary file beside `path`, renamed into place when
// whole (as write_study writes).
void write_image(const std::vector<unsigned char>& image, const std::string& path);

// A problem's declared parameters (core/parameter.hpp) as the /problems/<p>/parameters
// table: name, value, unit, kind, value_name (the name of the value, where it has one),
// default, allowed (the constraint in words), description.
const column_map<param_value>& parameters_columns();
// The `runs` table of a method's rows (docs/study-format.md); timing fields when timed.
const column_map<method_row>& runs_columns();
// The tables of /problems, in the schema's order (store/schema.cpp).
std::vector<schema::table> problems_tables();

}  // namespace stepbench
