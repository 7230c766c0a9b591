#pragma once
// The viewer's page and scripts (web/: index.html, viewer.js, and three.js from npm), compiled
// into the binary at build time (cmake/WebAssets.cmake), so the installed tool serves them from
// anywhere without a working directory or an internet connection.

#include <string_view>

namespace taiga::view {

struct WebAsset {
  std::string_view path;          ///< as requested, e.g. "/viewer.js"; "/" is the page
  std::string_view content_type;  ///< e.g. "text/javascript"
  std::string_view bytes;
};

/// The asset served at `path` (without a query), or nullptr.
const WebAsset* findWebAsset(std::string_view path);

}  // namespace taiga::view
