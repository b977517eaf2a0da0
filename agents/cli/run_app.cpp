// The parse-and-run block shared by the `drover` and `droverctl` executables.

#include <exception>
#include <iostream>

#include "agents/cli/command.hpp"

namespace drover::cli {

int run_app(CLI::App& app, const CommandContext& context, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  } catch (const std::exception& e) {
    // Commands turn expected failures into messages themselves; this is the last guard so
    // that nothing ever ends in an uncaught exception.
    std::cerr << "error: internal: " << e.what() << "\n";
    return kExitFailure;
  }
  // A tool's answer is what it printed: lost (a full disk, a closed pipe), the run failed.
  std::cout.flush();
  if (!std::cout) {
    std::cerr << "error: cannot write to standard output\n";
    return context.exit_code == kExitOk ? kExitFailure : context.exit_code;
  }
  return context.exit_code;
}

}  // namespace drover::cli
