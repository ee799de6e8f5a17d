#pragma once
/// \file
/// Shared helpers for the plugin host tests: fixture paths, scoped environment and directories, error
/// capture, and "is this library loaded" (dlopen with RTLD_NOLOAD, which never loads anything).

#include "impetus/core/error.hpp"
#include "impetus/plugins/host.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>

namespace impetus_test {

namespace fs = std::filesystem;

/// Where plugins/fixtures builds its libraries.
inline fs::path fixture_dir() { return fs::path(IMPETUS_FIXTURE_DIR); }
/// The fixture file `impetus_integrator_<name>.so`.
inline fs::path integrator_fixture(const std::string& name) {
  return fixture_dir() / ("impetus_integrator_" + name + ".so");
}

/// Sets or unsets an environment variable for the lifetime of the object, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) setenv(name, value->c_str(), 1);
    else unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) setenv(name_, old_->c_str(), 1);
    else unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

/// A fresh, empty directory removed (with its contents) at the end of the scope.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("impetus-plugin-test-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-" + tag);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  /// Copies `file` into this directory (optionally renamed); returns the copy's path.
  fs::path copy(const fs::path& file, const std::string& new_name = {}) const {
    const fs::path target = path_ / (new_name.empty() ? file.filename().string() : new_name);
    fs::copy_file(file, target, fs::copy_options::overwrite_existing);
    return target;
  }

 private:
  fs::path path_;
};

/// A host searching `dirs` first, then the default directory; IMPETUS_PLUGIN_PATH is ignored.
inline impetus::PluginHost host_with(const std::vector<fs::path>& dirs) {
  ScopedEnv no_env("IMPETUS_PLUGIN_PATH", std::nullopt);
  impetus::PluginHost host;
  host.prepend_directories(dirs);
  return host;
}
/// A host searching the fixture directory first.
inline impetus::PluginHost fixture_host() { return host_with({fixture_dir()}); }

/// The message of the impetus::Error `fn` throws; fails the test if it throws nothing or something else.
template <typename F>
std::string error_message(F&& fn) {
  try {
    fn();
  } catch (const impetus::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected impetus::Error, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected impetus::Error, nothing was thrown";
  return {};
}

/// Expects `text` to contain every one of `parts`.
inline void expect_contains(const std::string& text, std::initializer_list<std::string> parts) {
  for (const std::string& part : parts)
    EXPECT_NE(text.find(part), std::string::npos) << "missing \"" << part << "\" in:\n  " << text;
}

/// Whether the shared library `file` is loaded in this process.
inline bool is_loaded(const fs::path& file) {
  void* handle = dlopen(fs::canonical(file).c_str(), RTLD_NOW | RTLD_NOLOAD);
  if (handle != nullptr) dlclose(handle);  // NOLOAD still took a reference
  return handle != nullptr;
}

/// A request by name for the integrator `name`.
inline impetus::PluginRequest integrator_request(const std::string& name, const std::string& where = {}) {
  impetus::PluginRequest request;
  request.kind = impetus::ModuleKind::integrator;
  request.name = name;
  request.where = where;
  return request;
}

/// A scalar option as a scene would write it.
inline impetus::OptionValue option(const std::string& text, const std::string& where) {
  impetus::OptionValue value;
  value.text = text;
  value.where = where;
  return value;
}

}  // namespace impetus_test
