// Loading plugins (plugin/api.hpp): every command takes `--plugin PATH`
// (repeatable), CSTAB_PLUGIN_PATH lists more (':'-separated files), a
// matrix file's [defaults] `plugins` key more again. Loaded once per
// process, before any problem or method is looked up; a forked matrix
// worker inherits them.
#pragma once

#include <string>
#include <vector>

namespace cstab {

struct LoadedPlugin {
  std::string path;      // as resolved (realpath)
  std::string identity;  // "<size>-<content hash>" of the file
  std::vector<std::string> methods, problems;  // the names it added
};

// Loads the plugin at `path` and adds what it registers. Throws UsageError
// ("plugin PATH: ...", exit 2) for a missing or unreadable file, a shared
// object that is not a cstab plugin, one built against another cstab
// (ABI or build id), a missing symbol, a name already taken; nothing of it
// is then added. Loading the same file again does nothing.
void load_plugin(const std::string& path);
// The files listed in CSTAB_PLUGIN_PATH (empty entries skipped).
void load_plugins_from_environment();

const std::vector<LoadedPlugin>& loaded_plugins();
// The plugin a method or problem came from: its identity, "" if built in.
std::string origin_identity(const std::string& origin);

// Takes every `--plugin PATH` and `--plugin=PATH` out of `args`, in order.
std::vector<std::string> take_plugin_flags(std::vector<std::string>& args);

}  // namespace cstab
