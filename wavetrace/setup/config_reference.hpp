// docs/configuration.md, generated from the key table: what `wavetrace keys` prints and what
// ConfigKeys.DocsAreGeneratedFromTheTable compares with the file in the tree.
#pragma once

#include <string>

namespace wavetrace {

// Every section's keys as Markdown tables: key, type, default, range or choices, help.
std::string configuration_markdown();

}  // namespace wavetrace
