// A whole program's preview: the check of the program (check_program, the same moves, limits
// and extents cncd-check reports) with its path collected for display, and the JSON object
// program.preview answers and `cncd-check --preview` prints (docs/protocol.md).
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "cncd/pipeline/preview.hpp"
#include "cncd/pipeline/program_check.hpp"

namespace cncd::pipeline {

struct ProgramPreview {
  CheckReport report;
  Preview preview;
};

// Checks `program` with `options` (its preview member is set here) and collects its path.
ProgramPreview preview_program(const std::filesystem::path& program, CheckOptions options,
                               const PreviewOptions& preview);

// The preview as JSON: extents and counts as numbers, the polylines as base64 of little-endian
// arrays (float32 points, uint32 lines and counts, uint8 kinds).
nlohmann::json preview_json(const ProgramPreview& preview);

}  // namespace cncd::pipeline
