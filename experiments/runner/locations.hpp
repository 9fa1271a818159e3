#pragma once
/// Where the programs find their files, in the build tree and in an install
/// prefix alike (an installed program never needs the source tree):
///  - the asset cache: $ICD_CACHE_DIR, else <source>/assets in the build
///    tree, else $XDG_CACHE_HOME/icd (or ~/.cache/icd);
///  - the shipped scenes: PREFIX/share/icd/scenes when installed, the source
///    tree's experiments/scenes otherwise;
///  - an input file a scene names by a relative path: see resolve_input().
/// A program counts as installed when PREFIX/share/icd/scenes (the install
/// rule's folder, relative to PREFIX/bin) exists beside its folder.
#include <filesystem>
#include <string>

namespace icd::runner {

/// Folder of the running program (from /proc/self/exe).
std::filesystem::path program_dir();

/// Whether the running program is an installed one (see above).
bool installed();

/// The folder of the shipped scene files.
std::filesystem::path scenes_dir();

/// The default asset cache folder (see above); not created here.
std::filesystem::path default_cache_dir();

/// A relative input path `p` of a scene file in folder `scene_dir`, made
/// absolute: the first that exists of scene_dir/p, ./p, $ICD_DATA_DIR/p,
/// $ICD_DATA_DIR/<file name of p>, and (build tree only) <source>/p; when
/// none exists, scene_dir/p (so the error names it). Absolute paths are
/// returned as they are.
std::filesystem::path resolve_input(const std::filesystem::path& p,
                                    const std::filesystem::path& scene_dir);

}  // namespace icd::runner
