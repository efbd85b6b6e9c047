#pragma once
// glTF buffer and image URIs are relative references resolved against the model's folder. A
// model must not read files elsewhere (`../../etc/passwd`, absolute paths) unless the user
// allows it with --allow-external-files.
#include <string>

namespace shadel {

// Percent-decodes a URI reference ("%2e%2e/" is "../"); malformed escapes are kept verbatim.
std::string decodeUriPath(const std::string& uri);

// True if the (decoded) relative reference `uri` resolves outside the folder it is relative to:
// absolute, or with more "../" than it descends (checked lexically, like the resolution).
bool uriEscapesFolder(const std::string& uri);

// True if `path` lies inside `folder`, both lexically (after normalising "." and "..") and by
// real path (symbolic links resolved: a link in the folder to a file elsewhere is outside).
bool pathInsideFolder(const std::string& path, const std::string& folder);

} // namespace shadel
