#pragma once
// Minimal self-contained unit-test harness.
//
//   TEST_CASE("deck: continuation lines") { CHECK(1 + 1 == 2); }
//
// CHECK(cond), CHECK_EQ(a, b) (values printable with <<), CHECK_NEAR(a, b, tol) and
// CHECK_THROWS_AS(expr, Type) record a failure with file:line and the expression and let the
// test case continue. An exception escaping a test case fails it. The runner (test_main.cpp)
// runs every case whose name contains argv[1] and ends with the line "N passed, M failed".
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace unit_test {

struct TestCase {
  const char* name;
  void (*function)();
  const char* file;
  int line;
};

inline std::vector<TestCase>& registry() {
  static std::vector<TestCase> tests;
  return tests;
}

// Failed checks in the test case that is running.
inline int& failures_in_current_case() {
  static int count = 0;
  return count;
}

inline void report_failure(const char* file, int line, const std::string& what) {
  std::fprintf(stderr, "%s:%d: check failed: %s\n", file, line, what.c_str());
  ++failures_in_current_case();
}

struct Registrar {
  Registrar(const char* name, void (*function)(), const char* file, int line) {
    registry().push_back(TestCase{name, function, file, line});
  }
};

template <typename A, typename B>
void check_equal(const A& a, const B& b, const char* text, const char* file, int line) {
  if (a == b) return;
  std::ostringstream out;
  out << "CHECK_EQ(" << text << "): " << a << " != " << b;
  report_failure(file, line, out.str());
}

inline void check_near(double a, double b, double tolerance, const char* text, const char* file,
                       int line) {
  if (std::fabs(a - b) <= tolerance) return;  // false for NaN, which must fail
  std::ostringstream out;
  out.precision(17);
  out << "CHECK_NEAR(" << text << "): " << a << " vs " << b << " (tolerance " << tolerance
      << ")";
  report_failure(file, line, out.str());
}

// Runs the cases whose name contains `filter`; prints "N passed, M failed"; returns the exit
// status (non-zero when a case failed or none matched).
inline int run_all(const std::string& filter) {
  int passed = 0;
  int failed = 0;
  for (const TestCase& test : registry()) {
    if (std::string(test.name).find(filter) == std::string::npos) continue;
    failures_in_current_case() = 0;
    try {
      test.function();
    } catch (const std::exception& e) {
      report_failure(test.file, test.line, std::string("unexpected exception: ") + e.what());
    } catch (...) {
      report_failure(test.file, test.line, "unexpected exception of unknown type");
    }
    if (failures_in_current_case() == 0) {
      ++passed;
    } else {
      ++failed;
      std::fprintf(stderr, "%s:%d: FAILED test case '%s'\n", test.file, test.line, test.name);
    }
  }
  if (passed + failed == 0) std::fprintf(stderr, "no test case matches '%s'\n", filter.c_str());
  std::printf("%d passed, %d failed\n", passed, failed);
  return (failed > 0 || passed == 0) ? 1 : 0;
}

}  // namespace unit_test

#define UNIT_TEST_CONCAT_INNER(a, b) a##b
#define UNIT_TEST_CONCAT(a, b) UNIT_TEST_CONCAT_INNER(a, b)
#define UNIT_TEST_CASE_IMPL(name, function)                                          \
  static void function();                                                           \
  static const ::unit_test::Registrar UNIT_TEST_CONCAT(function, _registrar)(        \
      name, &function, __FILE__, __LINE__);                                         \
  static void function()
#define TEST_CASE(name) UNIT_TEST_CASE_IMPL(name, UNIT_TEST_CONCAT(unit_test_case_, __COUNTER__))

#define CHECK(condition)                                                            \
  do {                                                                              \
    if (!(condition)) ::unit_test::report_failure(__FILE__, __LINE__, "CHECK(" #condition ")"); \
  } while (false)

#define CHECK_EQ(a, b) ::unit_test::check_equal((a), (b), #a ", " #b, __FILE__, __LINE__)

#define CHECK_NEAR(a, b, tolerance) \
  ::unit_test::check_near((a), (b), (tolerance), #a ", " #b, __FILE__, __LINE__)

#define CHECK_THROWS_AS(expression, Type)                                                  \
  do {                                                                                     \
    bool unit_test_threw_expected = false;                                                 \
    std::string unit_test_other;                                                           \
    try {                                                                                  \
      static_cast<void>(expression);                                                       \
    } catch (const Type&) {                                                                \
      unit_test_threw_expected = true;                                                     \
    } catch (const std::exception& unit_test_error) {                                      \
      unit_test_other = std::string("a different exception: ") + unit_test_error.what();  \
    } catch (...) {                                                                        \
      unit_test_other = "an exception of unknown type";                                    \
    }                                                                                      \
    if (!unit_test_threw_expected) {                                                       \
      ::unit_test::report_failure(                                                         \
          __FILE__, __LINE__,                                                              \
          "CHECK_THROWS_AS(" #expression ", " #Type ") got " +                             \
              (unit_test_other.empty() ? std::string("no exception") : unit_test_other));  \
    }                                                                                      \
  } while (false)
