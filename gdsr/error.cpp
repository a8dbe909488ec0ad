#include "gdsr/error.hpp"

namespace gdsr {

void fail(const std::string& where, const std::string& msg) { throw Error(where + ": " + msg); }

}  // namespace gdsr
