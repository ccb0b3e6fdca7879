#pragma once
// Who holds a claim on a frame, and whether it is still there. An unfinished --progressive
// image (octray.samplesSoFar) is a claim held by the run writing it; it records its owner
// in the attribute octray.owner as "HOST:PID:START" (START: the process's start time in
// clock ticks after boot, /proc/PID/stat field 22, telling a reused PID apart). Another run
// renders over such a claim only when it is provably stale: the owner ran on this host and
// its process is gone. A claim from another host is honoured until its file is deleted.

#include <string>

namespace octray::batch {

// This process as an owner: "HOST:PID:START".
std::string current_owner();

// True when `owner` ("HOST:PID:START") ran on this host and no longer runs: no process has
// that PID, or the one that has it started at another time. An owner from another host, or
// one that cannot be checked, is not stale. An empty or malformed owner (an image written
// by an octray that did not record one) is stale.
bool owner_is_gone(const std::string& owner);

}  // namespace octray::batch
