#pragma once
// Scene files of the mfsi command: a path or the name of a built-in scene, and a scene's name.

#include "core/SceneConfig.hpp"

#include <filesystem>
#include <string>

/// \brief A path to a scene file, or the file of the built-in scene of that name; throws InputError.
std::filesystem::path resolveScene(const std::string& arg);
/// \brief The scene's `name`, or its file's stem.
std::string sceneName(const mfsi::SceneConfig& cfg, const std::filesystem::path& file);
