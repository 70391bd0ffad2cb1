// An accelerator and its options in one word, as --accel takes it on every command:
// TYPE[:key=value]..., e.g. "hmq:width=8:epsilon=pixel" or "auto:memory_budget=2GB".
#pragma once

#include <string>

#include "wavetrace/setup/config.hpp"

namespace wavetrace {

// Sets the keys the spec names: accel.type, accel.TYPE.key (accel.key for auto's
// memory_budget and max_error), and build.chunk_triangles, which is the build's, not the
// type's. Throws ConfigError naming an option that is not key=value or a key the schema lacks.
void apply_accelerator_spec(Config& config, const std::string& text);

}  // namespace wavetrace
