#pragma once
// Resume and claims: what an existing output file is to a batch render (a finished frame,
// an empty --placeholders claim, an unfinished --progressive pass claimed by the run
// writing it, or a damaged file), and claiming, taking over and releasing a frame's
// output. Who owns an unfinished pass: claim_owner.h.

#include <string>

namespace octray::batch {

// The attribute that marks an image written by a --progressive pass before the last one:
// --skip-existing does not count such a file as a finished frame.
inline constexpr const char* kSamplesSoFarAttribute = "octray.samplesSoFar";
// The run that writes an unfinished pass: its claim (claim_owner.h).
inline constexpr const char* kOwnerAttribute = "octray.owner";

// A finished frame: a non-empty file that is not an unfinished --progressive pass.
// An empty file is a --placeholders claim; an unfinished pass is a claim of its owner
// (claim_owner.h) while that run lives. An OpenEXR file whose chunks do not hold what its
// header implies (cut off, or its header lying about its pixel data) is damaged: resuming
// never takes it for a finished frame, nor renders over what it did not write.
enum class Existing { none, claim, finished, unfinished, damaged };

struct Found {
    Existing kind = Existing::none;
    std::string owner;  // octray.owner of an unfinished pass ("" if it has none)
    std::string error;  // why a damaged file cannot be read
};

// What is at `path`. A file that is not an OpenEXR (a PNG preview) is finished when it is
// not empty; an OpenEXR gets the chunk checks of `compare` without decoding its pixels.
Found existing_output(const std::string& path);

// Takes over a stale unfinished image at `path` for --placeholders: replaces it by an
// empty claim of this run. Two runs may find the same stale image; the one that holds the
// file's lock and still finds it stale under the lock wins, the other finds it changed
// and backs off. False if another run took it (or it cannot be locked).
bool take_over(const std::string& path);

// Claims `path` with an empty file; false if another run got there first. Throws IoError
// when the file cannot be created for another reason.
bool claim(const std::string& path);

// Gives a claim back after a failed or interrupted frame, if it is still an empty file.
void release_claim(const std::string& path);

}  // namespace octray::batch
