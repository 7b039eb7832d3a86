// SceneViewer::defaultWebRoot(): where the built front end is, found at run time. In a file of
// its own because it is compiled with the build tree's path, which differs between checkouts: the
// rest of the Scene Viewer then compiles the same everywhere (and ccache reuses it).
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "rp/gui/SceneViewer.hpp"

#ifndef RP_WEB_ROOT_BUILD
#define RP_WEB_ROOT_BUILD ""
#endif
#ifndef RP_WEB_ROOT_FROM_LIBDIR
#define RP_WEB_ROOT_FROM_LIBDIR "../share/roboticplatform/web"
#endif

namespace rp {

namespace {
// An object of the library: dladdr() of its address names the file the library was loaded from.
const char kLibraryAnchor = 0;

// The installed front end beside the library that holds this code (<libdir>/../share/...), found
// at run time so that an installed copy works from any prefix, moved or not; empty if unknown.
std::filesystem::path webRootBesideLibrary() {
  Dl_info info{};
  if (dladdr(&kLibraryAnchor, &info) == 0 || info.dli_fname == nullptr || info.dli_fname[0] == '\0') return {};
  std::error_code ec;
  std::filesystem::path library = std::filesystem::canonical(info.dli_fname, ec);
  if (ec) library = info.dli_fname;
  return (library.parent_path() / RP_WEB_ROOT_FROM_LIBDIR).lexically_normal();
}
}  // namespace

std::string SceneViewer::defaultWebRoot() {
  if (const char* env = std::getenv("RP_WEB_ROOT"); env && *env) return env;
  std::error_code ec;
  const std::filesystem::path installed = webRootBesideLibrary();
  if (!installed.empty() && std::filesystem::exists(installed / "index.html", ec)) return installed.string();
  if (std::string(RP_WEB_ROOT_BUILD).size() && std::filesystem::exists(std::string(RP_WEB_ROOT_BUILD) + "/index.html", ec))
    return RP_WEB_ROOT_BUILD;
  if (!installed.empty()) return installed.string();  // serves the "front end not built" page
  return RP_WEB_ROOT_BUILD;
}

}  // namespace rp
