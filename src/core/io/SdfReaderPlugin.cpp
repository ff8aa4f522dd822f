#include <dlfcn.h>

#include <string>

#include "SdfReaderPlugin.hpp"
#include "XmlValues.hpp"
#include "mobility_analysis/io/SdfReader.hpp"

namespace mobility_analysis {

namespace {

/// The loaded plugin's reader, or why there is none.
struct SdfPlugin {
  io_detail::SdfReadFunction read = nullptr;
  std::string error;
};

std::string dlopenError() {
  const char* error = dlerror();
  return error != nullptr ? error : "unknown error";
}

/// The plugin beside this library (the devel space's lib/, or the installed package's), else wherever the
/// dynamic loader finds it.
SdfPlugin loadSdfPlugin() {
  SdfPlugin plugin;
  std::string path = io_detail::kSdfPluginFile;
  Dl_info self{};
  if (dladdr(reinterpret_cast<void*>(&readSdf), &self) != 0 && self.dli_fname != nullptr) {
    const std::string library = self.dli_fname;
    const size_t slash = library.find_last_of('/');
    if (slash != std::string::npos)
      path = library.substr(0, slash + 1) + io_detail::kSdfPluginFile;
  }
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr && path != io_detail::kSdfPluginFile)
    handle = dlopen(io_detail::kSdfPluginFile, RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    plugin.error = dlopenError();
    return plugin;
  }
  using Entry = io_detail::SdfReadFunction (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(handle, io_detail::kSdfPluginSymbol));
  if (entry == nullptr) {
    plugin.error = dlopenError();
    return plugin;
  }
  plugin.read = entry();
  return plugin;
}

}  // namespace

// libsdformat and ignition-math compile about 80 regular expressions in their static initialisers: some
// 280 million instructions, 50 ms, at the start of every program linking them, where reading a four-bar takes
// a millisecond. So they live in a plugin (SdfReader.cpp) loaded the first time an SDF file is read; the
// handle is kept for the life of the process (static local: loaded once, thread-safe).
Result<Mechanism> readSdf(const std::string& sdfText, const std::string& fileName) {
  static const SdfPlugin plugin = loadSdfPlugin();
  if (plugin.read == nullptr) {
    return makeDiagnostic(io_detail::baseName(fileName), "sdf", "",
                          "SDFormat support is not available (" + std::string(io_detail::kSdfPluginFile) +
                              " could not be loaded: " + plugin.error + ")");
  }
  return plugin.read(sdfText, fileName);
}

}  // namespace mobility_analysis
