#include "cncd/pipeline/program_preview.hpp"

#include <openssl/evp.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::pipeline {
namespace {

// Little-endian bytes of each value, whatever the host's order.
template <typename T>
std::vector<unsigned char> little_endian(const std::vector<T>& values) {
  std::vector<unsigned char> bytes(values.size() * sizeof(T));
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::uint32_t word = 0;
    if constexpr (sizeof(T) == 4) {
      std::memcpy(&word, &values[i], 4);
    } else {
      word = static_cast<std::uint32_t>(values[i]);
    }
    for (std::size_t b = 0; b < sizeof(T); ++b)
      bytes[i * sizeof(T) + b] = static_cast<unsigned char>(word >> (8 * b));
  }
  return bytes;
}

std::string base64(const std::vector<unsigned char>& bytes) {
  std::string text(4 * ((bytes.size() + 2) / 3) + 1, '\0');
  const int written = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(text.data()), bytes.data(),
                                      static_cast<int>(bytes.size()));
  text.resize(static_cast<std::size_t>(written));
  return text;
}

std::vector<std::uint8_t> kind_codes(const std::vector<PieceKind>& kinds) {
  std::vector<std::uint8_t> codes;
  codes.reserve(kinds.size());
  for (const PieceKind kind : kinds)
    codes.push_back(static_cast<std::uint8_t>(kind));
  return codes;
}

}  // namespace

ProgramPreview preview_program(const std::filesystem::path& program, CheckOptions options,
                               const PreviewOptions& preview) {
  // Arcs come as chords within a tenth of the builder's tolerance of them (program_check.cpp):
  // the builder gets 10/11 of the tolerance asked for, and the drawing stays within the whole.
  PreviewOptions thinning = preview;
  thinning.tolerance = preview.tolerance * 10 / 11;
  PreviewBuilder builder(thinning);
  options.preview = &builder;
  ProgramPreview out;
  out.report = check_program(program, options);
  out.preview = builder.finish();
  out.preview.tolerance += thinning.tolerance / 10;
  return out;
}

nlohmann::json preview_json(const ProgramPreview& preview) {
  using nlohmann::json;
  const CheckReport& report = preview.report;
  const Preview& path = preview.preview;
  json extents = json::object();
  for (std::size_t axis = 0; axis < interp::kAxes; ++axis) {
    if (!report.moved[axis]) continue;
    extents[std::string(1, config::kAxisLetters[axis])] = {report.min[axis], report.max[axis]};
  }
  json frames = json::array();
  for (const PreviewFrame& frame : path.frames) {
    frames.push_back(
        {{"origin", frame.origin}, {"g92", frame.g92}, {"rotation", frame.rotation_deg}});
  }
  json kinds = json::array();
  for (const PieceKind kind :
       {PieceKind::rapid, PieceKind::feed, PieceKind::arc, PieceKind::cycle, PieceKind::probe})
    kinds.push_back(piece_kind_name(kind));
  json out = {
      {"units", report.inch_machine ? "in" : "mm"},
      {"coordinates", "machine"},
      {"complete", !report.error && !report.stopped},
      {"error", report.error ? json(report.error->to_string()) : json(nullptr)},
      {"stopped", report.stopped ? json(report.stopped->to_string()) : json(nullptr)},
      {"extents", std::move(extents)},
      {"blocks", report.blocks},
      {"tolerance", path.tolerance},
      {"source_points", path.source_points},
      {"points", path.lines.size()},
      {"polylines", path.kinds.size()},
      {"kinds", std::move(kinds)},
      {"frames", std::move(frames)},
      {"encoding", "base64 little-endian"},
      {"polyline_kind", base64(kind_codes(path.kinds))},
      {"polyline_points", base64(little_endian(path.counts))},
      {"polyline_frame", base64(little_endian(path.frame_of))},
      {"xyz", base64(little_endian(path.xyz))},
      {"line", base64(little_endian(path.lines))},
  };
  return out;
}

}  // namespace cncd::pipeline
