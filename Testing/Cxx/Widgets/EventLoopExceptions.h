#pragma once
// The widget test program's QApplication catches any exception that reaches the event loop (which must never
// happen), prints it and counts it here, so a test can assert that none escaped.

namespace fct::test {

/// Exceptions caught at the event loop so far in this test program.
int eventLoopExceptionCount();

}  // namespace fct::test
