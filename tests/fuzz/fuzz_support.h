// Shared by the libFuzzer targets: a scratch file per process (the loaders under test read
// files, so each input is written to one first) and the tiny database the seeds come from.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

#include <nlohmann/json.hpp>

namespace nphand::fuzz {

// A path in a per-process scratch folder (under /dev/shm when it exists).
std::filesystem::path ScratchPath(const char* name);
// Replaces the file at `path` with `bytes`.
void WriteBytes(const std::filesystem::path& path, std::span<const uint8_t> bytes);
// The header of `nphand db build --grasps 1 --gestures none --directions 2` (20 entries),
// which scripts/fuzz.sh builds for the seeds.
const nlohmann::json& SeedHeader();
// Opens `path` as a database and, if it opens, reads every field of every record and
// describes it, as `db info` and the feature study do. Returns whether it opened.
bool OpenAndReadEverything(const std::filesystem::path& path);

}  // namespace nphand::fuzz
