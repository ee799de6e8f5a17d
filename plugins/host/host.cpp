// The plugin host: search path, checks, loading and unloading. The contract is in
// impetus/plugins/host.hpp; every message this file produces is listed in plugins/README.md.

#include "impetus/plugins/host.hpp"

#include "impetus/core/error.hpp"
#include "impetus/plugins/layout.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <string_view>
#include <system_error>
#include <utility>

#ifndef IMPETUS_PLUGIN_SUBDIR
#error "IMPETUS_PLUGIN_SUBDIR must be defined by the build (see plugins/host/CMakeLists.txt)"
#endif

namespace fs = std::filesystem;

namespace impetus {

/// One dlopen'ed library that passed the ABI checks. dlclose'd when its last owner (the host's
/// transient use or a module's deleter) lets go.
class LoadedLibrary {
 public:
  LoadedLibrary(void* handle, fs::path canonical_path) : path(std::move(canonical_path)), handle_(handle) {}
  ~LoadedLibrary() {
    if (handle_ != nullptr) dlclose(handle_);
  }
  LoadedLibrary(const LoadedLibrary&) = delete;
  LoadedLibrary& operator=(const LoadedLibrary&) = delete;

  void* handle() const { return handle_; }

  const fs::path path;                          ///< canonical
  const PluginDescriptor* descriptor = nullptr;  ///< static data inside the library

 private:
  void* handle_;
};

namespace {

constexpr std::string_view kFilePrefix = "impetus_";
constexpr std::string_view kFileSuffix = ".so";
constexpr ModuleKind kAllKinds[] = {ModuleKind::integrator, ModuleKind::detector, ModuleKind::resolver};

std::string kind_with_article(std::uint32_t kind) {
  if (kind < 1 || kind > 3) return "an unknown kind (" + std::to_string(kind) + ")";
  const char* name = module_kind_name(static_cast<ModuleKind>(kind));
  return std::string(name[0] == 'i' ? "an " : "a ") + name;
}
std::string kind_with_article(ModuleKind kind) { return kind_with_article(static_cast<std::uint32_t>(kind)); }

std::string display(const fs::path& path) { return path.string(); }

std::string hex(std::uint64_t word) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016" PRIx64, word);
  return text;
}

std::string join(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (const std::string& item : items) {
    if (!out.empty()) out += separator;
    out += item;
  }
  return out;
}

/// `impetus_<kind>_<name>.so`.
std::string file_name_for(ModuleKind kind, const std::string& name) {
  return std::string(kFilePrefix) + module_kind_name(kind) + "_" + name + std::string(kFileSuffix);
}

/// The kind and name a file name promises, if it follows `impetus_<kind>_<name>.so`.
std::optional<std::pair<ModuleKind, std::string>> parse_file_name(std::string_view file_name) {
  if (!file_name.starts_with(kFilePrefix) || !file_name.ends_with(kFileSuffix)) return std::nullopt;
  file_name.remove_prefix(kFilePrefix.size());
  file_name.remove_suffix(kFileSuffix.size());
  for (ModuleKind kind : kAllKinds) {
    const std::string kind_part = std::string(module_kind_name(kind)) + "_";
    if (file_name.size() > kind_part.size() && file_name.starts_with(kind_part))
      return std::make_pair(kind, std::string(file_name.substr(kind_part.size())));
  }
  return std::nullopt;
}

fs::path absolute_normal(const fs::path& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  return (ec ? path : absolute).lexically_normal();
}

void append_unique(std::vector<fs::path>& list, const fs::path& dir) {
  if (std::find(list.begin(), list.end(), dir) == list.end()) list.push_back(dir);
}

/// The `impetus_*.so` files of one directory: those reachable by name first (so they win a duplicate),
/// then the rest, each group sorted by name. A missing or unreadable directory has none.
std::vector<fs::path> plugin_files(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  fs::directory_iterator it(dir, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // Not only regular files: load() reports a directory or FIFO named like a plugin as a failure.
    if (name.starts_with(kFilePrefix) && name.ends_with(kFileSuffix)) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    const bool a_named = parse_file_name(a.filename().string()).has_value();
    const bool b_named = parse_file_name(b.filename().string()).has_value();
    return a_named != b_named ? a_named : a.filename() < b.filename();
  });
  return files;
}

/// "" if the descriptor declares `kind` and (when non-empty) `name`; otherwise what differs.
/// `source` says where the expectation comes from ("as its file name says", "as requested").
std::string check_identity(const PluginDescriptor& d, ModuleKind kind, const std::string& name,
                           const char* source) {
  if (d.kind != static_cast<std::uint32_t>(kind))
    return "wrong kind: it declares " + kind_with_article(d.kind) + " named '" + d.name + "', expected " +
           kind_with_article(kind) + ", " + source;
  if (!name.empty() && name != d.name)
    return "name mismatch: it declares '" + std::string(d.name) + "', expected '" + name + "', " + source;
  return {};
}

/// "" if every layout word of the plugin matches the host's; otherwise the types that differ, each with
/// both words.
std::string layout_mismatch(const LayoutWords& plugin) {
  const LayoutWords host = plugin_layout_words();
  std::vector<std::string> differing;
  for (std::size_t type = 0; type < kLayoutTypeCount; ++type)
    if (plugin[type] != host[type])
      differing.push_back(std::string(kLayoutTypeNames[type]) + " (plugin: " + hex(plugin[type]) +
                          ", host: " + hex(host[type]) + ")");
  if (differing.empty()) return {};
  return "layout mismatch: the plugin was built with a different layout of " + join(differing, ", ") +
         "; rebuild it against this Impetus";
}

/// Owns a module: destroys it with its own plugin's code, then lets go of the library (which may
/// unload it), in that order.
struct ModuleDeleter {
  PluginDestroyFn destroy;
  std::shared_ptr<LoadedLibrary> library;
  void operator()(void* module) noexcept {
    if (module != nullptr) destroy(module);
    library.reset();
  }
};

// Its address locates libimpetus_plugin_host.so for dladdr.
const char kLocator = 0;

}  // namespace

PluginHost::PluginHost() {
  // IMPETUS_PLUGIN_PATH: colon-separated; empty entries are ignored (not "the current directory").
  if (const char* env = std::getenv("IMPETUS_PLUGIN_PATH")) {
    std::string_view rest(env);
    while (!rest.empty()) {
      const std::size_t colon = rest.find(':');
      const std::string_view entry = rest.substr(0, colon);
      if (!entry.empty()) append_unique(search_path_, absolute_normal(fs::path(entry)));
      rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
    }
  }
  const fs::path fallback = default_directory();
  if (!fallback.empty()) append_unique(search_path_, fallback);
}

PluginHost::~PluginHost() = default;

void PluginHost::prepend_directories(const std::vector<fs::path>& dirs) {
  std::vector<fs::path> path;
  for (const fs::path& dir : dirs) append_unique(path, absolute_normal(dir));
  for (const fs::path& dir : search_path_) append_unique(path, dir);
  search_path_ = std::move(path);
}

fs::path PluginHost::default_directory() {
  Dl_info info{};
  if (dladdr(&kLocator, &info) == 0 || info.dli_fname == nullptr || info.dli_fname[0] == '\0') return {};
  // Canonical, so a symlinked libimpetus_plugin_host.so still finds the plugins next to the real file.
  std::error_code ec;
  fs::path library = fs::canonical(info.dli_fname, ec);
  if (ec) library = absolute_normal(info.dli_fname);
  return library.parent_path() / IMPETUS_PLUGIN_SUBDIR;
}

std::shared_ptr<Integrator> PluginHost::create_integrator(const PluginRequest& request) {
  PluginRequest typed = request;  // the function decides the kind
  typed.kind = ModuleKind::integrator;
  return std::static_pointer_cast<Integrator>(create(typed));
}

std::shared_ptr<CollisionDetector> PluginHost::create_detector(const PluginRequest& request) {
  PluginRequest typed = request;
  typed.kind = ModuleKind::detector;
  return std::static_pointer_cast<CollisionDetector>(create(typed));
}

std::shared_ptr<CollisionResolver> PluginHost::create_resolver(const PluginRequest& request) {
  PluginRequest typed = request;
  typed.kind = ModuleKind::resolver;
  return std::static_pointer_cast<CollisionResolver>(create(typed));
}

std::shared_ptr<LoadedLibrary> PluginHost::load(const fs::path& file, std::string& reason) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(file, ec);
  if (ec) {
    reason = "cannot open the file: " + ec.message();
    return nullptr;
  }
  // dlopen blocks forever on a FIFO and reads a device without end: only a regular file is a library.
  if (const fs::file_status status = fs::status(canonical, ec); !fs::is_regular_file(status)) {
    reason = fs::is_directory(status) ? "is a directory, not a shared library"
                                      : "is not a regular file (a device, FIFO or socket), not a shared library";
    return nullptr;
  }
  std::erase_if(open_, [](const auto& entry) { return entry.second.expired(); });
  if (auto it = open_.find(canonical); it != open_.end())
    if (auto library = it->second.lock()) return library;

  dlerror();  // clear any stale message
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* text = dlerror();
    reason = std::string("dlopen failed: ") + (text != nullptr ? text : "no reason given");
    return nullptr;
  }
  auto library = std::make_shared<LoadedLibrary>(handle, canonical);  // dlcloses on every early return

  void* symbol = dlsym(handle, kPluginEntrySymbol);
  if (symbol == nullptr) {
    reason = std::string("not an Impetus plugin: it does not export the entry symbol '") + kPluginEntrySymbol +
             "' (declare the plugin with IMPETUS_PLUGIN and build it with impetus_add_plugin)";
    return nullptr;
  }
  PluginEntryFn entry = nullptr;
  static_assert(sizeof entry == sizeof symbol);
  std::memcpy(&entry, &symbol, sizeof entry);  // object → function pointer, as POSIX dlsym requires
  const PluginDescriptor* d = entry();
  if (d == nullptr) {
    reason = std::string("its entry symbol '") + kPluginEntrySymbol + "' returned no descriptor";
    return nullptr;
  }
  // Only the first two fields are read before the size is known to match.
  if (d->abi_version != kPluginAbiVersion) {
    reason = "ABI version mismatch: the plugin was built for plugin ABI " + std::to_string(d->abi_version) +
             ", this Impetus uses ABI " + std::to_string(kPluginAbiVersion) +
             " (rebuild the plugin against this Impetus)";
    return nullptr;
  }
  if (d->descriptor_size != sizeof(PluginDescriptor)) {
    reason = "descriptor size mismatch: the plugin's PluginDescriptor is " + std::to_string(d->descriptor_size) +
             " bytes, this Impetus's is " + std::to_string(sizeof(PluginDescriptor)) +
             " bytes (the plugin was built against a different impetus/plugins/abi.hpp)";
    return nullptr;
  }
  const std::uint64_t host_word = plugin_config_word();
  if (d->config_word != host_word) {
    reason = "build configuration mismatch: the plugin was built with [" + describe_config_word(d->config_word) +
             "] (" + hex(d->config_word) + "), this Impetus with [" + describe_config_word(host_word) + "] (" +
             hex(host_word) + ")";
    return nullptr;
  }
  reason = layout_mismatch(d->layout_words);
  if (!reason.empty()) return nullptr;
  if (d->kind < 1 || d->kind > 3) {
    reason = "invalid descriptor: it declares " + kind_with_article(d->kind);
    return nullptr;
  }
  if (d->name == nullptr || d->name[0] == '\0' || d->create == nullptr || d->destroy == nullptr) {
    reason = "invalid descriptor: its name, create or destroy is missing";
    return nullptr;
  }
  library->descriptor = d;
  open_[canonical] = library;
  return library;
}

fs::path PluginHost::find_by_name(ModuleKind kind, const std::string& name) const {
  const std::string file_name = file_name_for(kind, name);
  for (const fs::path& dir : search_path_) {
    std::error_code ec;
    if (fs::exists(fs::symlink_status(dir / file_name, ec))) return dir / file_name;  // load() checks its type
  }
  return {};
}

std::string PluginHost::unknown_name_message(const PluginRequest& request) {
  const std::string kind = module_kind_name(request.kind);
  // Loading every library is acceptable here: this is already an error path.
  const PluginListing listing = discover();
  std::vector<std::string> searched;
  for (const fs::path& dir : listing.searched) {
    std::error_code ec;
    searched.push_back(display(dir) + (fs::is_directory(dir, ec) ? "" : " (missing)"));
  }
  std::set<std::string> names;
  for (const PluginInfo& info : listing.plugins)
    if (info.kind == request.kind) names.insert(info.name);
  std::string message = "no " + kind + " plugin named '" + request.name + "'; searched: " +
                        (searched.empty() ? std::string("no directories") : join(searched, ", ")) +
                        "; available " + kind + "s: " +
                        (names.empty() ? std::string("none") : join(std::vector<std::string>(names.begin(), names.end()), ", "));
  if (!listing.failures.empty())
    message += " (" + std::to_string(listing.failures.size()) +
               " other libraries there failed to load; `impetus plugins` says why)";
  message += "; IMPETUS_PLUGIN_PATH adds directories";
  return message;
}

std::shared_ptr<void> PluginHost::create(const PluginRequest& request) {
  const std::string prefix = request.where.empty() ? "" : request.where + ": ";
  const std::string kind = module_kind_name(request.kind);
  const std::string what = kind + " plugin" + (request.name.empty() ? "" : " '" + request.name + "'");

  fs::path file;
  if (!request.file.empty()) {
    file = absolute_normal(request.file);
    std::error_code ec;
    if (!fs::exists(file, ec)) throw Error(prefix + "cannot load " + what + ": file " + display(file) + " does not exist");
  } else {
    if (request.name.empty()) throw Error(prefix + "no " + kind + " plugin given: the name is empty");
    if (request.name.find('/') != std::string::npos)
      throw Error(prefix + "'" + request.name + "' is not a plugin name (it contains '/'; give a file with `path:`)");
    file = find_by_name(request.kind, request.name);
    if (file.empty()) throw Error(prefix + unknown_name_message(request));
  }
  const std::string failed = prefix + "cannot load " + what + " from " + display(file) + ": ";

  std::string reason;
  std::shared_ptr<LoadedLibrary> library = load(file, reason);
  if (library)
    reason = check_identity(*library->descriptor, request.kind, request.name,
                            request.file.empty() ? "as its file name says" : "as requested");
  if (!reason.empty()) throw Error(failed + reason);
  const PluginDescriptor& d = *library->descriptor;

  // Two different libraries for one kind and name would make "which one ran" depend on load order.
  const auto key = std::make_pair(request.kind, std::string(d.name));
  if (auto it = registered_.find(key); it != registered_.end() && it->second != library->path) {
    auto other = open_.find(it->second);
    if (other != open_.end() && !other->second.expired())
      throw Error(failed + "duplicate: " + kind + " plugin '" + d.name + "' is already loaded from " +
                  display(it->second) + "; one process cannot use two different libraries for it");
  }
  registered_[key] = library->path;

  const std::string label = "plugin '" + std::string(d.name) + "' (" + kind + ")";
  ModuleOptions no_options(label);
  ModuleOptions* options = request.options != nullptr ? request.options : &no_options;
  char error[1024] = {};
  void* raw = d.create(options, error, sizeof error);
  error[sizeof error - 1] = '\0';  // the plugin may have filled the buffer without a terminator
  if (raw == nullptr)
    throw Error(failed + "its factory failed: " +
                (error[0] != '\0' ? std::string(error) : "it returned no module and no message"));
  // From here the module is owned: an exception below destroys it through its own plugin.
  std::shared_ptr<void> module(raw, ModuleDeleter{d.destroy, library});

  const std::vector<std::string> unknown = options->unread();
  if (!unknown.empty()) {
    std::vector<std::string> described;
    for (const std::string& key_name : unknown) {
      const std::string& where = options->values().at(key_name).where;
      described.push_back("'" + key_name + "'" + (where.empty() ? "" : " (" + where + ")"));
    }
    // What the plugin asked for is, by construction, what it understands.
    const std::vector<std::string> known_list(options->known().begin(), options->known().end());
    throw Error(prefix + label + " has no option " + join(described, " or ") + "; " +
                (known_list.empty() ? "it takes no options" : "its options are: " + join(known_list, ", ")) +
                " (plugin file " + display(file) + ")");
  }
  return module;
}

PluginListing PluginHost::discover() {
  PluginListing listing;
  listing.searched = search_path_;
  // First place each kind+name was seen: directory index and file.
  std::map<std::pair<ModuleKind, std::string>, std::pair<std::size_t, fs::path>> first;
  for (std::size_t index = 0; index < search_path_.size(); ++index) {
    for (const fs::path& file : plugin_files(search_path_[index])) {
      std::string reason;
      const std::shared_ptr<LoadedLibrary> library = load(file, reason);
      const auto promised = parse_file_name(file.filename().string());
      if (library && promised)
        reason = check_identity(*library->descriptor, promised->first, promised->second, "as its file name says");
      if (!reason.empty()) {
        listing.failures.push_back({file, reason});
        continue;
      }
      const PluginDescriptor& d = *library->descriptor;
      PluginInfo info;
      info.kind = static_cast<ModuleKind>(d.kind);
      info.name = d.name;
      info.version = d.version != nullptr ? d.version : "";
      info.summary = d.summary != nullptr ? d.summary : "";
      info.path = file;
      const auto [it, inserted] = first.try_emplace({info.kind, info.name}, index, file);
      if (!inserted) {
        if (it->second.first == index) {
          listing.failures.push_back({file, "duplicate: " + std::string(module_kind_name(info.kind)) +
                                                " plugin '" + info.name + "' is also provided by " +
                                                display(it->second.second) + " in the same directory"});
          continue;
        }
        info.shadowed = true;
      }
      listing.plugins.push_back(std::move(info));
    }
  }
  return listing;
}

}  // namespace impetus
