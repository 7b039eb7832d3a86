// The settings reference that `rp-objects --settings [CLASS]` prints: every registered class's
// rp.cfg settings (from the classes' own setting schemas) as Markdown tables; docs/settings.md
// holds the same text and a test compares the two.
#pragma once

#include <ostream>
#include <string>

namespace rp::apps {

// Prints the reference of the class `className` (empty: every registered class, sorted).
// Returns false (and prints nothing) if `className` is not registered.
bool printSettingsReference(std::ostream& out, const std::string& className);

}  // namespace rp::apps
