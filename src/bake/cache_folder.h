#pragma once
// The folder every cache file lives in (bakes, texture-streaming files, environments, distance
// fields, pipeline caches), and whether it can be trusted.
//
// A cache folder is trusted when it is a directory owned by this user that other users cannot
// write to. A folder the engine creates is private (0700). A folder that fails the check (say a
// /tmp/shadel-cache-UID made beforehand by someone else) is never read or written: the run goes
// on without a cache and says so once.
#include <string>

namespace shadel {

// $SHADEL_CACHE_DIR if set, else $XDG_CACHE_HOME/shadel, else $HOME/.cache/shadel, else
// /tmp/shadel-cache-UID. Empty or relative XDG_CACHE_HOME and HOME are ignored (the XDG spec
// says so: a relative path would put the cache wherever the command happens to run, and an empty
// one at /shadel).
std::string defaultCacheFolder();

// Creates `dir` if missing (private) and checks it. Returns "" if it is usable, else why not.
std::string checkCacheFolder(const std::string& dir);

// The cache folder to use: `requested` (--cache-dir), or the default when it is empty; "" (run
// without a cache) when that folder is not trusted, with one warning per folder and process.
std::string usableCacheFolder(const std::string& requested);

} // namespace shadel
