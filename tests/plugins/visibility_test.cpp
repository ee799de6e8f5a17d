// A plugin built with impetus_add_plugin() exports exactly one symbol, the entry point, and no
// STB_GNU_UNIQUE symbol (which would make the library impossible to unload). Reads the ELF dynamic
// symbol table directly, so the test needs no external tool.
#include "plugin_test_support.hpp"

#include <elf.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <set>

namespace {

using namespace impetus_test;

/// The defined, non-local dynamic symbols of a 64-bit ELF file, and whether any is STB_GNU_UNIQUE.
struct DynamicSymbols {
  std::set<std::string> names;
  std::set<std::string> unique;
  std::string error;  ///< non-empty if the file could not be read as ELF64
};

template <typename T>
bool read_at(const std::vector<char>& data, std::size_t offset, T& out) {
  if (offset > data.size() || data.size() - offset < sizeof(T)) return false;
  std::memcpy(&out, data.data() + offset, sizeof(T));
  return true;
}

DynamicSymbols dynamic_symbols(const fs::path& file) {
  DynamicSymbols result;
  std::ifstream in(file, std::ios::binary);
  const std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Elf64_Ehdr header{};
  if (!read_at(data, 0, header) || std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 ||
      header.e_ident[EI_CLASS] != ELFCLASS64) {
    result.error = "not an ELF64 file";
    return result;
  }
  std::vector<Elf64_Shdr> sections(header.e_shnum);
  for (std::size_t i = 0; i < sections.size(); ++i)
    if (!read_at(data, header.e_shoff + i * header.e_shentsize, sections[i])) {
      result.error = "truncated section table";
      return result;
    }
  for (const Elf64_Shdr& section : sections) {
    if (section.sh_type != SHT_DYNSYM || section.sh_entsize == 0) continue;
    if (section.sh_link >= sections.size()) {
      result.error = "bad string table link";
      return result;
    }
    const Elf64_Shdr& strings = sections[section.sh_link];
    for (std::size_t i = 0; i < section.sh_size / section.sh_entsize; ++i) {
      Elf64_Sym symbol{};
      if (!read_at(data, section.sh_offset + i * section.sh_entsize, symbol)) {
        result.error = "truncated symbol table";
        return result;
      }
      const unsigned bind = ELF64_ST_BIND(symbol.st_info);
      if (symbol.st_shndx == SHN_UNDEF || bind == STB_LOCAL || symbol.st_name >= strings.sh_size) continue;
      const char* begin = data.data() + strings.sh_offset + symbol.st_name;
      const std::string name(begin, strnlen(begin, strings.sh_size - symbol.st_name));
      result.names.insert(name);
      if (bind == STB_GNU_UNIQUE) result.unique.insert(name);
    }
  }
  return result;
}

void expect_only_the_entry_symbol(const fs::path& file) {
  const DynamicSymbols symbols = dynamic_symbols(file);
  ASSERT_TRUE(symbols.error.empty()) << file << ": " << symbols.error;
  EXPECT_EQ(symbols.names, std::set<std::string>{impetus::kPluginEntrySymbol}) << file;
  EXPECT_TRUE(symbols.unique.empty()) << file << " has STB_GNU_UNIQUE symbols and cannot be unloaded";
}

TEST(PluginVisibility, TheReaderSeesTheSymbolsOfTheHostLibrary) {
  // Guards the test itself: libimpetus_plugin_host.so (<lib>/, above <lib>/impetus/plugins) exports the host.
  const fs::path host =
      impetus::PluginHost::default_directory().parent_path().parent_path() / "libimpetus_plugin_host.so";
  const DynamicSymbols symbols = dynamic_symbols(host);
  ASSERT_TRUE(symbols.error.empty()) << host << ": " << symbols.error;
  EXPECT_GT(symbols.names.size(), 1u);
  EXPECT_EQ(symbols.names.count("_ZN7impetus10PluginHost8discoverEv"), 1u) << "PluginHost::discover()";
}

TEST(PluginVisibility, FixturesBuiltWithImpetusAddPluginExportOnlyTheEntrySymbol) {
  // Both use the option API (std::map, std::set, std::string), whose template code must stay hidden.
  expect_only_the_entry_symbol(integrator_fixture("fixture_good"));
  expect_only_the_entry_symbol(integrator_fixture("my_integrator"));
}

TEST(PluginVisibility, ShippedPluginsExportOnlyTheEntrySymbol) {
  std::error_code ec;
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(IMPETUS_PLUGIN_DIR, ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("impetus_") || !name.ends_with(".so")) continue;
    SCOPED_TRACE(name);
    expect_only_the_entry_symbol(entry.path());
    ++checked;
  }
  EXPECT_GE(checked, 5) << "the shipped plugins (2 integrators, fcl, ledas, mirtich) are missing from "
                        << IMPETUS_PLUGIN_DIR;
}

}  // namespace
