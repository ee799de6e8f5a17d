// import_mesh: checks the file, then has it read in a separate process (the default) or in this one
// (IMPETUS_MESH_IMPORT=in-process): the text formats by text_mesh_reader.cpp at double precision, the
// rest by assimp (assimp_reader.cpp); the process, import_process.cpp and tools/mesh_import_helper.cpp.

#include "impetus/assets/mesh_import.hpp"

#include "import_process.hpp"
#include "mesh_file_checks.hpp"
#include "text_mesh_reader.hpp"

namespace impetus::assets {

ImportedMesh import_mesh(const std::filesystem::path& file, const ImportOptions& options) {
  const std::uintmax_t size = detail::check_mesh_file(file);
  const detail::IsolationSettings settings = detail::isolation_settings(file, size);
  if (!settings.isolated) return detail::read_mesh_file(file, options);
  return detail::import_isolated(file, options, settings);
}

}  // namespace impetus::assets
