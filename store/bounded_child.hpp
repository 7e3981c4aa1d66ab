#pragma once
// Work on untrusted files in a child process. HDF5 1.10 trusts sizes stored in a file
// where no call of its API can check them first (store/study_reader.cpp says where), so a
// damaged file can make it crash, loop or allocate without bound: in a child, that ends
// the child, and the command says so in one line.
#include <sys/types.h>

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace stepbench {

// In a child just forked: stop it past `cpu_seconds` of CPU time (SIGXCPU) and make its
// allocations fail past `memory_bytes` (not under AddressSanitizer, which reserves
// terabytes of address space for itself).
void bound_child(long cpu_seconds, std::size_t memory_bytes);

// The memory bound of a child that works on files of `file_bytes` in all: 2 GiB for
// HDF5's work, plus the files, each held up to three times (ours, HDF5's copy, its core
// file).
constexpr std::size_t child_memory_bound(std::size_t file_bytes) { return (std::size_t{2} << 30) + 3 * file_bytes; }

// Everything a child writes to `fd` until it closes it (or ends).
std::string read_to_end(int fd);

// How a child that was waited for with `status` ended, when the work in it did not end
// by itself: "damaged: <doing> did not end within N s of CPU time (HDF5 looping on it)",
// or "damaged: <doing> crashes the HDF5 library (SIGSEGV)" (a signal; "exit 1" for a
// sanitizer's report), or "<doing> was stopped (SIGINT)" for a signal from outside.
std::string abnormal_end(int status, long cpu_seconds, std::string_view doing);

// Runs `work` (a command's body: its exit code, or an exception) in a child bounded as
// above. What it prints on stderr is held and printed here once it has ended by itself;
// then its code is returned, or its exception thrown again (std::invalid_argument as
// such, any other as std::runtime_error, with the same text). When it did not end by
// itself, `on_abnormal_end(abnormal_end(...))` is called and must throw.
int run_in_bounded_child(const std::function<int()>& work, long cpu_seconds, std::size_t memory_bytes,
                         std::string_view doing, const std::function<void(const std::string&)>& on_abnormal_end);

}  // namespace stepbench
