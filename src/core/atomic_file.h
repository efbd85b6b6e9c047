#pragma once
// Whole-file writes that either complete or leave nothing behind.
//
// A regular file is written to a temporary file in the same folder (so the final rename stays on
// one file system and is atomic), flushed, checked, and renamed over the target: readers never
// see a partial file, and a failed write (full disk, quota, I/O error) removes the temporary
// file and leaves any previous target untouched. An existing non-regular target (a character
// device such as /dev/null, /dev/full or /dev/stdout, a pipe) is written in place, because
// renaming over it would replace the device node; its write errors are still reported.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace shadel {

// Returns "" on success, else one line "<path>: <strerror reason>" (naming the file that failed,
// which may be the temporary file next to path).
std::string writeFileAtomically(const std::string& path, const void* data, size_t size);

// The same for a cache entry (bake, environment, distance field), which is never written
// through what stands at the path: a symbolic link, pipe or device there is replaced by the new
// regular file (the rename replaces the folder entry, not what it points to).
std::string writeCacheEntry(const std::string& path, const void* data, size_t size);

// Reads a whole cache entry: only a regular file that is not a symbolic link, of at most
// maxBytes, without waiting on a pipe. Returns "" or why not: "missing", "a symbolic link",
// "not a regular file", the size over maxBytes, a read error. Callers treat every reason as
// "rebuild the entry".
std::string readCacheEntry(const std::string& path, uint64_t maxBytes, std::vector<uint8_t>& bytes);

// Returns "" if path looks writable without creating it: not a directory, its folder exists and
// is writable (or it is an existing writable non-regular file). Else "<path>: <reason>".
std::string checkFileCreatable(const std::string& path);

} // namespace shadel
