// The one error type of the gdsr libraries (gdsr/, train/, infer/; autograd/ and nn/ use
// ag::Error) and the one way to raise it. Library code never prints or exits: it throws a
// one-line message that names where the problem is, and the command line prints
// "gdsr: error: <message>" and exits 1.
#pragma once

#include <stdexcept>
#include <string>

namespace gdsr {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws Error("<where>: <msg>"). `where` names the input at fault (a file path, with
// ":<line>" where known) or, for a bad argument, the source file's stem ("patches").
[[noreturn]] void fail(const std::string& where, const std::string& msg);

}  // namespace gdsr
