#pragma once
/// Opening input files safely: every reader checks that its input is a
/// regular file (not a folder, device or FIFO such as /dev/zero) and within
/// the size limit of its format before reading a byte, so that no input can
/// make a reader hang or allocate without bound. Also the helpers that keep
/// file contents out of messages raw (byte escapes) and accept a UTF-8
/// byte-order mark in text formats.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace icd {

/// Size limits of the input files, in bytes, per format. With the readers'
/// own caps (header counts checked against the file size, at most 2^31 - 1
/// elements, 2^24 `.sph` node lines, 2^20 JSON values) they bound the memory
/// a reader can use; the limits are listed in
/// experiments/studies/reliability/README.md.
namespace file_limits {
inline constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
/// Scene files (JSON): hand-written, a few kB.
inline constexpr std::uint64_t kScene = 64 * kMiB;
/// Raw surface meshes (OFF, OBJ, PLY, STL): about 1.3 million triangles in
/// binary STL, 1 million vertices and 2 million faces in OFF.
inline constexpr std::uint64_t kSurfaceMesh = 64 * kMiB;
/// VTU files (the meshes of asset bundles, sphere sets): a dense surface of
/// about 500,000 vertices as icd-preprocess writes it.
inline constexpr std::uint64_t kVtu = 64 * kMiB;
/// `.sph` sphere trees (the toolkit's text format).
inline constexpr std::uint64_t kSph = 64 * kMiB;
/// `bundle.icdb`, the binary part of an asset bundle (rigid links and sphere
/// tree: about 60 bytes per dense vertex).
inline constexpr std::uint64_t kBundle = 128 * kMiB;
}  // namespace file_limits

/// Checks that `path` names an existing regular file of at most `max_bytes`
/// bytes and returns its size. `what` names the kind of file in the message
/// ("scene file", "mesh"). Throws InputError "<path>: cannot open file: no
/// such file", "<path>: cannot open file: not a regular file (a directory)",
/// or "<path>: <what> of N bytes is larger than the limit of M MiB".
std::uint64_t check_input_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                               std::string_view what);

/// The bytes of a file that passes check_input_file(). Never reads more than
/// `max_bytes` + 1 bytes (a file that grows while it is read is refused too).
/// Throws InputError naming the file on any failure.
std::string read_input_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                            std::string_view what);

/// `bytes` for a message: printable ASCII kept, every other byte (control
/// characters, NUL, bytes >= 0x80) written as \xNN; at most `max_chars` input
/// bytes, then "...".
std::string escape_bytes(std::string_view bytes, std::size_t max_chars = 80);

/// The UTF-8 byte-order mark EF BB BF.
inline constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

/// `text` without a leading UTF-8 byte-order mark (unchanged if it has none).
inline std::string_view strip_utf8_bom(std::string_view text) {
  return text.starts_with(kUtf8Bom) ? text.substr(kUtf8Bom.size()) : text;
}

}  // namespace icd
