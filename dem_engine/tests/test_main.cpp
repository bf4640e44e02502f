// Runs the registered unit tests; argv[1], when given, selects the test cases whose name
// contains it.
#include <string>

#include "unit_test.h"

int main(int argc, char** argv) {
  const std::string filter = argc > 1 ? argv[1] : "";
  return unit_test::run_all(filter);
}
