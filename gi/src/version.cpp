#include <gi/version.h>

namespace gi {

const char* version() { return "0.1.0"; }

}  // namespace gi
