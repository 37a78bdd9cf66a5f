#include <dicestack/regressors/registry.hpp>

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cstdlib>

#include <dicestack/core/error.hpp>

namespace dicestack {

void RegressorRegistry::add(RegressorInfo info) { add(std::move(info), registering_source_); }

void RegressorRegistry::add(RegressorInfo info, std::string source) {
  info.source = std::move(source);
  if (const auto it = entries_.find(info.name); it != entries_.end())
    throw ConfigError("regressor \"" + info.name + "\" registered twice (" + it->second.source + ", and " +
                      info.source + ")");
  if (info.name.empty() || !info.factory) throw ConfigError("a regressor needs a name and a factory");
  std::string name = info.name;
  entries_.emplace(std::move(name), std::move(info));
}

const RegressorInfo& RegressorRegistry::info(std::string_view name) const { return registered_entry(entries_, name, "regressor"); }

std::unique_ptr<Regressor> RegressorRegistry::create(std::string_view name,
                                                     const std::vector<std::string>& assignments) const {
  const RegressorInfo& i = info(name);
  return i.factory(i.name, Params(i.params, assignments, i.name));
}

std::vector<std::string> RegressorRegistry::names() const { return registered_names(entries_); }

void RegressorRegistry::load_plugin(const std::filesystem::path& library) {
  const std::string who = "plugin " + library.string();
  const auto canonical = std::filesystem::weakly_canonical(library);
  if (std::find(loaded_.begin(), loaded_.end(), canonical) != loaded_.end()) return;
  if (!std::filesystem::exists(library)) throw PluginError(who + ": no such file");
  // RTLD_LOCAL keeps plugins apart; they share our libraries (one registry) through their
  // own dependency on libdicestack_regressor_api. Handles stay open: registered factories live there.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw PluginError(who + ": cannot load: " + dlerror());
  using Entry = const DicestackPluginV1* (*)();
  void* symbol = dlsym(handle, "dicestack_plugin_v1");
  if (!symbol) {
    dlclose(handle);
    throw PluginError(who + ": not a dicestack plugin (no symbol dicestack_plugin_v1)");
  }
  // Calling a symbol that is data, not code, would crash: ask the dynamic linker what it is.
  Dl_info info{};
  void* extra = nullptr;
  const bool found = dladdr1(symbol, &info, &extra, RTLD_DL_SYMENT) != 0;
  const auto* elf = static_cast<const ElfW(Sym)*>(extra);
  if (!found || !elf ||
      (ELF64_ST_TYPE(elf->st_info) != STT_FUNC && ELF64_ST_TYPE(elf->st_info) != STT_GNU_IFUNC)) {
    dlclose(handle);
    throw PluginError(who + ": dicestack_plugin_v1 is not a function; not a dicestack plugin");
  }
  const DicestackPluginV1* p = reinterpret_cast<Entry>(symbol)();
  // The ABI version first: another ABI's record may have another layout.
  if (p && p->abi_version == DICESTACK_PLUGIN_ABI_VERSION && (!p->dicestack_version || !p->stdlib || !p->register_regressors))
    throw PluginError(who + ": its plugin record has a null field; not a dicestack plugin");
  const std::string ours = "ABI " + std::to_string(DICESTACK_PLUGIN_ABI_VERSION) + " (" DICESTACK_VERSION ", " +
                           DICESTACK_STDLIB_TAG + ")";
  if (!p || p->abi_version != DICESTACK_PLUGIN_ABI_VERSION || std::string(p->stdlib) != DICESTACK_STDLIB_TAG) {
    auto text = [](const char* t) { return std::string(t ? t : "?"); };
    const std::string theirs = p ? "ABI " + std::to_string(p->abi_version) + " (" + text(p->dicestack_version) + ", " +
                                       text(p->stdlib) + ")"
                                 : "an unknown ABI";
    throw PluginError(who + ": built for dicestack " + theirs + "; this is " + ours +
                      " - rebuild it with find_package(dicestack " DICESTACK_STRINGIFY(DICESTACK_VERSION_MAJOR) "." DICESTACK_STRINGIFY(DICESTACK_VERSION_MINOR) ")");
  }
  registering_source_ = "plugin " + library.string();
  try {
    p->register_regressors(this);
  } catch (...) {
    registering_source_ = "built-in";
    throw;
  }
  registering_source_ = "built-in";
  loaded_.push_back(canonical);
}

std::vector<std::filesystem::path> RegressorRegistry::load_plugins_from_environment() {
  std::vector<std::filesystem::path> loaded;
  const char* env = std::getenv("DICESTACK_PLUGIN_PATH");
  if (!env) return loaded;
  std::string_view rest(env);
  while (!rest.empty()) {
    const auto colon = rest.find(':');
    const std::filesystem::path entry(std::string(rest.substr(0, colon)));
    rest = colon == std::string_view::npos ? std::string_view{} : rest.substr(colon + 1);
    if (entry.empty()) continue;
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(entry)) {
      for (const auto& f : std::filesystem::directory_iterator(entry))
        if (f.path().extension() == ".so") files.push_back(f.path());
      std::sort(files.begin(), files.end());
    } else {
      files.push_back(entry);
    }
    for (const auto& f : files) {
      load_plugin(f);
      loaded.push_back(f);
    }
  }
  return loaded;
}

}  // namespace dicestack
