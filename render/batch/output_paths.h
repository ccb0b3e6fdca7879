#pragma once
// Output files of a batch render: which directory entry a write replaces (so that two
// spellings of one file are told to be the same), and creating the missing directories
// above the outputs before the first frame renders.

#include <string>
#include <vector>

#include "render/batch/plan.h"

namespace octray::batch {

// What a write to `path` replaces (octray writes a temporary and renames it over the
// target): the directory entry, as the device and inode of the parent directory plus the
// file name. Two paths with one identity are one file however they are spelled (".",
// "..", symlinks). When the parent does not exist yet, its lexically normal absolute path
// stands in for it.
std::string output_identity(const std::string& path);

// The directory part of output_identity: for `dir` ("" is the current directory), a key
// such that output_identity(dir / name) == directory_identity(dir) + name.
std::string directory_identity(const std::string& dir);

// Creates the missing directories above every output and preview of `jobs` (as Blender
// does), top down, and returns those it created, in order; fails before the render when
// one cannot be created or a directory clearly cannot be written, rather than after hours
// of rendering (the writes themselves still report anything this misses); refuses an
// output that exists and is not a regular file (check_output_target: a device node, a
// FIFO). Another run creating one at the same time is no error. Throws IoError naming the
// file and why.
std::vector<std::string> prepare_output_directories(const std::vector<BatchJob>& jobs);

}  // namespace octray::batch
