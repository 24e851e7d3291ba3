#pragma once
// Files embedded into the library at build time (viewer_assets.cpp, written
// by embed_assets.cmake): the page template and Debian's three.js.

#include <string_view>

namespace saloam::viewer_assets {

/// viewer.html: the page, with /*SALOAM_...*/ placeholders for the scripts and the data.
extern const std::string_view kPageTemplate;
/// live.html: the page of a run in progress (`--serve`), with the same placeholders.
extern const std::string_view kLivePageTemplate;
/// viewer_common.css and viewer_common.js: what both pages share.
extern const std::string_view kCommonCss;
extern const std::string_view kCommonJs;
/// three.min.js and examples/js/controls/OrbitControls.js; empty when
/// libjs-three was not installed when saloam was configured.
extern const std::string_view kThreeJs;
extern const std::string_view kOrbitControlsJs;

}  // namespace saloam::viewer_assets
