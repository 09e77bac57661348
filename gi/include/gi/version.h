#pragma once
// Version of the GI module (the methods land in later milestones; see DESIGN.md).

namespace gi {

/// "major.minor.patch" of the gi library.
const char* version();

}  // namespace gi
