// From an environment spec (the command line's --env, a session's "environment") to the light: reads
// the .hdr file or builds the sky, and projects it.
#pragma once

#include "solver/environment_light.h"

#include <filesystem>

namespace waxwork {

// Relative file paths resolve against `base` (a session's folder; empty: the working directory).
// Throws FileError naming the file for an unreadable, non-HDR or truncated one, and
// InvalidArgumentError naming it for a zero-size image or a non-finite, negative or absurd pixel.
EnvironmentLight load_environment(const EnvironmentSpec& spec, const std::filesystem::path& base = {});

}  // namespace waxwork
