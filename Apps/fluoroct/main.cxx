// fluoroct: the FluoroCT command-line tool (thin entry point; each subcommand lives in its own *Command.cxx).
#include <fmt/core.h>

#include <exception>
#include <new>

#include "CliSupport.h"

int main(int argc, char** argv) {
  using namespace fct::cli;
  CLI::App app{"FluoroCT: register a pre-operative CT to intra-operative fluoroscopic X-ray images"};
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "fluoroct 0.1.0");
  CommandAction action;
  registerInfoCommand(app, action);
  registerPhantomCommand(app, action);
  registerPoseCommand(app, action);
  registerDrrCommand(app, action);
  registerViewsCommand(app, action);
  registerSimulateCommand(app, action);
  registerRegisterCommand(app, action);
  registerTrackCommand(app, action);
  registerTreCommand(app, action);
  registerEvaluateCommand(app, action);
  registerDewarpCalibrateCommand(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::Success&) {
    return 0;  // e.g. --xml printed the Slicer module description
  } catch (const CLI::ParseError& e) {
    return reportError(fmt::format("{} (run 'fluoroct --help' or 'fluoroct COMMAND --help')", e.what()));
  }
  try {
    return action ? action() : reportError("no command given; run 'fluoroct --help'");
  } catch (const std::bad_alloc&) {
    return reportError("out of memory; try a smaller volume or detector");
  } catch (const std::exception& e) {
    return reportError(fmt::format("unexpected internal error: {}; please report it with the command line used", e.what()));
  }
}
