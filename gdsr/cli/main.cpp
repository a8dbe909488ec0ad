// The gdsr command line. Subcommands live in their own files (see commands.hpp); every
// error surfaces here as one line "gdsr: error: <message>" on stderr and exit status 1.
#include "autograd/runtime.hpp"
#include "gdsr/cli/commands.hpp"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string>

namespace {
int fail(const std::string& msg) {
  std::string line = msg;
  // nlohmann-json prefixes its messages with "[json.exception.<kind>.<id>] ": not for users.
  const size_t j = line.find("[json.exception");
  if (j != std::string::npos && line.find("] ", j) != std::string::npos)
    line = line.substr(0, j) + "bad JSON: " + line.substr(line.find("] ", j) + 2);
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  std::cerr << "gdsr: error: " << line << "\n";
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  ag::configure_runtime(argv);  // heap reuse and passive OpenMP waiting (autograd/runtime.hpp)
  CLI::App app{"gdsr: neural garment dynamic super-resolution"};
  app.require_subcommand(1);
  add_demo_command(app);
  add_data_command(app);
  add_train_command(app);
  add_weights_command(app);
  add_infer_command(app);
  add_eval_command(app);
  add_export_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    return fail(e.what());
  } catch (const std::bad_alloc&) {
    return fail("out of memory: a size in an input file or a flag is too large for this machine");
  } catch (const std::length_error&) {
    return fail("a size in an input file or a flag is too large (beyond what a container can hold)");
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  return 0;
}
