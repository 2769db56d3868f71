// ROS bags for the programs that read them (sdpslam/io/bags.h): the bag plugin
// (bag_common.h: BagPlugin) is loaded the first time a bag is met, and LogReader and
// Ros2BagWriter use what it holds.
#include <dlfcn.h>
#include <link.h>
#include <sys/stat.h>

#include <cstring>
#include <string>
#include <vector>

#include "bag_common.h"
#include "sdpslam/io/bags.h"

#ifndef SDPSLAM_BAG_PLUGIN_BUILD
#error "SDPSLAM_BAG_PLUGIN_BUILD names the build (tools/bags/CMakeLists.txt)"
#endif
#ifndef SDPSLAM_BAG_PLUGIN_INSTALLED_DIR
#error "SDPSLAM_BAG_PLUGIN_INSTALLED_DIR is where an installed plugin lies (tools/bags/CMakeLists.txt)"
#endif

namespace sdpslam::io {
namespace {

struct Loaded {
  const detail::BagPlugin* plugin = nullptr;
  std::string error;  // why there is none
};

std::string dl_error() {
  const char* e = dlerror();
  return e != nullptr ? e : "unknown error";
}

// The folders the program's own libraries are searched in (its run path with $ORIGIN
// expanded: the build tree's plugin folder, or $ORIGIN/../lib/.../sdpslam once installed;
// LD_LIBRARY_PATH; the system's), as the dynamic loader reports them for the program.
// Asked of the program rather than left to dlopen(name), which searches the run path of
// the object that calls it: under the sanitizers that is their runtime library, not us.
std::vector<std::string> program_search_path() {
  std::vector<std::string> out;
  void* self = dlopen(nullptr, RTLD_NOW);
  if (self == nullptr) return out;
  Dl_serinfo size{};
  if (dlinfo(self, RTLD_DI_SERINFOSIZE, &size) == 0 && size.dls_size >= sizeof(Dl_serinfo)) {
    std::vector<unsigned char> buffer(size.dls_size);  // the header, then the folders' names
    void* raw = buffer.data();                          // (aligned as operator new aligns)
    if (dlinfo(self, RTLD_DI_SERINFOSIZE, raw) == 0 && dlinfo(self, RTLD_DI_SERINFO, raw) == 0) {
      const auto* serinfo = static_cast<const Dl_serinfo*>(raw);
      for (unsigned int i = 0; i < serinfo->dls_cnt; ++i) out.emplace_back(serinfo->dls_serpath[i].dls_name);
    }
  }
  dlclose(self);
  return out;
}

// First in the program's search path, then where `make install` puts it. Never unloaded:
// what it made may live on.
Loaded load() {
  Loaded out;
  void* handle = nullptr;
  std::string why;
  std::vector<std::string> tried = program_search_path();
  tried.emplace_back(SDPSLAM_BAG_PLUGIN_INSTALLED_DIR);
  for (const std::string& dir : tried) {
    const std::string file = dir + "/" + detail::kBagPluginFile;
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) continue;
    handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle != nullptr) break;
    why += (why.empty() ? "" : "; ") + dl_error();
  }
  if (handle == nullptr) {
    if (why.empty()) {
      why = "not found in the program's library path nor in " SDPSLAM_BAG_PLUGIN_INSTALLED_DIR;
    }
    out.error = std::string("reading ROS bags needs sdpslam's bag plugin ") + detail::kBagPluginFile +
                " (installed with the sdpslam command), which cannot be loaded: " + why;
    return out;
  }
  void* entry = dlsym(handle, detail::kBagPluginEntry);
  if (entry == nullptr) {
    out.error = std::string(detail::kBagPluginFile) + ": not sdpslam's bag plugin (no " + detail::kBagPluginEntry + ")";
    return out;
  }
  detail::BagPluginEntry get = nullptr;
  std::memcpy(&get, &entry, sizeof get);  // POSIX: a function's address from dlsym
  const detail::BagPlugin* plugin = get();
  if (plugin == nullptr || std::strcmp(plugin->build, SDPSLAM_BAG_PLUGIN_BUILD) != 0) {
    out.error = std::string(detail::kBagPluginFile) + " is from another build of sdpslam (" +
                (plugin != nullptr ? plugin->build : "none") + ") than this program (" + SDPSLAM_BAG_PLUGIN_BUILD +
                "): install both from one build";
    return out;
  }
  out.plugin = plugin;
  return out;
}

const Loaded& loaded() {
  static const Loaded l = load();
  return l;
}

// A reader from the plugin, loaded at the first call; the error says why there is none.
template <std::unique_ptr<detail::BagSource> (*detail::BagPlugin::*Make)()>
std::unique_ptr<detail::BagSource> make_source(std::string* error) {
  const Loaded& l = loaded();
  if (l.plugin == nullptr) {
    *error = l.error;
    return nullptr;
  }
  return (l.plugin->*Make)();
}

}  // namespace

void enable_bag_formats() {
  detail::g_make_ros1_source = &make_source<&detail::BagPlugin::make_ros1_source>;
  detail::g_make_ros2_source = &make_source<&detail::BagPlugin::make_ros2_source>;
}

bool load_bag_plugin(std::string* error) {
  const Loaded& l = loaded();
  if (l.plugin == nullptr && error != nullptr) *error = l.error;
  return l.plugin != nullptr;
}

bool ros2_bags_supported() {
  const Loaded& l = loaded();
  return l.plugin != nullptr && l.plugin->ros2_supported;
}

Ros2BagWriter::Ros2BagWriter() = default;
Ros2BagWriter::~Ros2BagWriter() = default;

bool Ros2BagWriter::open(const std::string& folder, std::string* error) {
  const Loaded& l = loaded();
  if (l.plugin == nullptr) {
    *error = folder + ": " + l.error;
    return false;
  }
  impl_ = l.plugin->make_ros2_writer();
  return impl_->open(folder, error);
}

void Ros2BagWriter::odom(const OdomRecord& r) {
  if (impl_ != nullptr) impl_->odom(r);
}

bool Ros2BagWriter::laser(const LaserRecord& r, std::string* error) {
  if (impl_ == nullptr) {
    *error = "the bag is not open";
    return false;
  }
  return impl_->laser(r, error);
}

std::uint64_t Ros2BagWriter::scans_written() const { return impl_ != nullptr ? impl_->scans_written() : 0U; }
std::uint64_t Ros2BagWriter::scans_without_odometry() const {
  return impl_ != nullptr ? impl_->scans_without_odometry() : 0U;
}

bool Ros2BagWriter::close(std::string* error) {
  if (impl_ == nullptr) {
    *error = "the bag is not open";
    return false;
  }
  return impl_->close(error);
}

}  // namespace sdpslam::io
