// Tests of the deck front-end: line rules, substitution, variables, built-in commands,
// equal-style formulas and error locations.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "deck/command.h"
#include "deck/errors.h"
#include "deck/eval_context.h"
#include "deck/input.h"
#include "deck/line_lexer_internal.h"
#include "deck/variables.h"
#include "unit_test.h"

namespace fs = std::filesystem;
using dem::Command;
using dem::DeckError;
using dem::EngineError;
using dem::Input;
using dem::SourceLocation;
using dem::Variables;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Simulation stand-in: a few thermo keywords, groups "all" and "top", compute "press",
// fix "wall". Records group-function calls.
class FakeContext : public dem::EvalContext {
 public:
  double step = 0.0;
  mutable std::vector<std::string> calls;

  std::optional<double> thermo_keyword(const std::string& name) const override {
    if (name == "step") return step;
    if (name == "dt") return 1e-5;
    if (name == "atoms") return 1200.0;
    if (name == "ke") return 0.25;
    return std::nullopt;
  }
  double group_function(const std::string& function,
                        const std::vector<std::string>& args) const override {
    std::string call = function + "(";
    for (std::size_t i = 0; i < args.size(); ++i) call += (i ? "," : "") + args[i];
    calls.push_back(call + ")");
    if (args[0] != "all" && args[0] != "top") throw EngineError("unknown group '" + args[0] + "'");
    const double scale = args[0] == "all" ? 1.0 : 0.5;
    if (function == "count") return 42.0 * scale;
    if (function == "mass") return 0.75 * scale;
    if (function == "ke") return 2.0 * scale;
    if (function == "xcm") return args[1] == "z" ? 0.125 : 0.0;
    if (function == "vcm") return args[1] == "y" ? -0.5 : 0.0;
    if (function == "bound") return args[1] == "zmax" ? 0.03 : -0.03;
    throw EngineError("unexpected group function " + function);
  }
  double compute_value(const std::string& id, int index) const override {
    if (id != "press") throw EngineError("unknown compute '" + id + "'");
    return 100.0 + index;
  }
  double fix_value(const std::string& id, int index) const override {
    if (id != "wall") throw EngineError("unknown fix '" + id + "'");
    return 10.0 * index + 1.0;
  }
};

// Records every command and message; `on_execute` adds behaviour for chosen commands.
class Recorder : public dem::CommandHandler {
 public:
  FakeContext ctx;
  std::vector<Command> commands;
  std::vector<std::string> messages;
  std::vector<std::pair<std::string, bool>> logs;
  std::function<void(const Command&)> on_execute;

  void execute(const Command& command) override {
    commands.push_back(command);
    if (on_execute) on_execute(command);
  }
  void message(const std::string& text) override { messages.push_back(text); }
  void open_log(const std::string& path, bool append) override { logs.emplace_back(path, append); }
  const dem::EvalContext& eval_context() const override { return ctx; }
};

// Fresh directory under the system temp dir, removed with its contents on destruction.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() /
            ("dem_deck_test_" + std::to_string(stamp) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  // Writes `text` to `name` in the directory and returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    // A new file rather than a truncated one: some file systems flush on truncate-rewrite.
    std::error_code ec;
    fs::remove(file, ec);
    std::ofstream out(file, std::ios::binary);
    out << text;
    return file.string();
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Makes `dir` the working directory for the guard's lifetime.
class WorkingDirectory {
 public:
  explicit WorkingDirectory(const fs::path& dir) : saved_(fs::current_path()) {
    fs::current_path(dir);
  }
  ~WorkingDirectory() {
    std::error_code ec;
    fs::current_path(saved_, ec);
  }
  WorkingDirectory(const WorkingDirectory&) = delete;
  WorkingDirectory& operator=(const WorkingDirectory&) = delete;

 private:
  fs::path saved_;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::vector<std::string> args(std::initializer_list<const char*> words) {
  return std::vector<std::string>(words.begin(), words.end());
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Runs `deck` written as file deck.in in a fresh temp dir; returns the deck path.
std::string run_deck(Recorder& recorder, Variables& vars, const std::string& deck) {
  static TempDir dir;
  const std::string path = dir.write("deck.in", deck);
  Input input(recorder, vars);
  input.run_file(path);
  return path;
}

// The DeckError that running `deck` raises, if any.
std::optional<DeckError> deck_error(const std::string& deck, Recorder* recorder = nullptr) {
  Recorder local;
  Variables vars;
  try {
    run_deck(recorder ? *recorder : local, vars, deck);
  } catch (const DeckError& e) {
    return e;
  }
  return std::nullopt;
}

double eval(const std::string& formula) {
  const FakeContext ctx;
  const Variables vars;
  return dem::evaluate_expression(formula, vars, ctx);
}

// Message of the EngineError that evaluating `formula` raises ("" when none is raised).
std::string eval_error(const std::string& formula, const Variables& vars = Variables()) {
  const FakeContext ctx;
  try {
    dem::evaluate_expression(formula, vars, ctx);
  } catch (const EngineError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Line rules
// ---------------------------------------------------------------------------------------------

TEST_CASE("lexer: comments, quotes and word splitting") {
  using dem::deck_lexer::split_words;
  using dem::deck_lexer::strip_comment;
  CHECK_EQ(strip_comment("fix 1 all nve # integrate"), std::string("fix 1 all nve "));
  CHECK_EQ(strip_comment("print \"a # b\" # c"), std::string("print \"a # b\" "));
  CHECK_EQ(strip_comment("x 'it''s' #"), std::string("x 'it''s' "));
  CHECK_EQ(strip_comment("a b#c"), std::string("a b"));
  CHECK_EQ(strip_comment("\"\"\"multi\n# still text\n\"\"\" # gone"),
           std::string("\"\"\"multi\n# still text\n\"\"\" "));

  const auto words = split_words("  fix  \"a b\" 'c \"d\"' \"\" it's \t\"\"\"e\n'f'\"\"\" ");
  CHECK_EQ(words.size(), std::size_t{6});
  if (words.size() == 6) {
    CHECK_EQ(words[0].text, std::string("fix"));
    CHECK(!words[0].quoted);
    CHECK_EQ(words[1].text, std::string("a b"));
    CHECK(words[1].quoted);
    CHECK_EQ(words[2].text, std::string("c \"d\""));
    CHECK_EQ(words[3].text, std::string(""));
    CHECK(words[3].quoted);
    CHECK_EQ(words[4].text, std::string("it's"));
    CHECK_EQ(words[5].text, std::string("e\n'f'"));
  }
  CHECK_THROWS_AS(split_words("print \"abc"), EngineError);
  CHECK_THROWS_AS(split_words("print 'abc"), EngineError);
  CHECK_THROWS_AS(split_words("print \"\"\"abc\"\""), EngineError);
  CHECK_THROWS_AS(split_words("print \"abc\"def"), EngineError);
  CHECK(dem::deck_lexer::ends_inside_triple_quote("print \"\"\"abc"));
  CHECK(!dem::deck_lexer::ends_inside_triple_quote("print \"\"\"abc\"\"\""));
  CHECK(!dem::deck_lexer::ends_inside_triple_quote("print x # \"\"\""));
}

TEST_CASE("lexer: number formats") {
  using dem::deck_lexer::format_number;
  CHECK_EQ(format_number("%.3f", 3.14159), std::string("3.142"));
  CHECK_EQ(format_number("%.15g", 1.0 / 3.0), std::string("0.333333333333333"));
  CHECK_EQ(format_number("%e", 1024.0), std::string("1.024000e+03"));
  CHECK_EQ(format_number("x=%08.2f%%", -2.5), std::string("x=-0002.50%"));
  CHECK_THROWS_AS(format_number("%d", 1.0), EngineError);
  CHECK_THROWS_AS(format_number("%s", 1.0), EngineError);
  CHECK_THROWS_AS(format_number("%f %f", 1.0), EngineError);
  CHECK_THROWS_AS(format_number("none", 1.0), EngineError);
  CHECK_THROWS_AS(format_number("%9999f", 1.0), EngineError);
}

TEST_CASE("deck: continuation joins lines and keeps the first line number") {
  Recorder r;
  Variables vars;
  const std::string path = run_deck(r, vars,
                                    "fix 1 all &\n"
                                    "    nve/sphere\n"
                                    "# comment line\n"
                                    "\n"
                                    "pair_style gran &   \n"
                                    "  model hertz &\n"
                                    "  tangential history\r\n"
                                    "run 10\n"
                                    "cmd ab&\n"
                                    "cd");
  CHECK_EQ(r.commands.size(), std::size_t{4});
  if (r.commands.size() != 4) return;
  CHECK_EQ(r.commands[0].name, std::string("fix"));
  CHECK(r.commands[0].args == args({"1", "all", "nve/sphere"}));
  CHECK_EQ(r.commands[0].where.line, 1);
  CHECK_EQ(r.commands[0].where.file, path);
  CHECK(r.commands[1].args == args({"gran", "model", "hertz", "tangential", "history"}));
  CHECK_EQ(r.commands[1].where.line, 5);
  CHECK_EQ(r.commands[2].name, std::string("run"));
  CHECK_EQ(r.commands[2].where.line, 8);
  // LAMMPS appends the next line directly where the '&' was.
  CHECK(r.commands[3].args == args({"abcd"}));
  CHECK_EQ(r.commands[3].where.line, 9);
}

TEST_CASE("deck: comments and quotes") {
  Recorder r;
  Variables vars;
  run_deck(r, vars,
           "cmd a # trailing comment\n"
           "cmd \"a # not a comment\" 'single # too' b#c\n"
           "cmd it's fine\n"
           "cmd \"\"\"triple \"quoted\" 'text'\n"
           "second # line\"\"\" end\n"
           "cmd \"\"\n");
  CHECK_EQ(r.commands.size(), std::size_t{5});
  if (r.commands.size() != 5) return;
  CHECK(r.commands[0].args == args({"a"}));
  CHECK(r.commands[1].args == args({"a # not a comment", "single # too", "b"}));
  CHECK(r.commands[2].args == args({"it's", "fine"}));
  CHECK(r.commands[3].args == args({"triple \"quoted\" 'text'\nsecond # line", "end"}));
  CHECK_EQ(r.commands[3].where.line, 4);
  CHECK(r.commands[4].args == args({""}));
  CHECK_EQ(r.commands[4].where.line, 6);
}

TEST_CASE("deck: substitution forms") {
  Recorder r;
  Variables vars;
  run_deck(r, vars,
           "variable n index 7\n"
           "variable name string box\n"
           "variable f equal 1/3\n"
           "variable e equal 2*v_n\n"
           "cmd $n ${name} ${f} ${e} $(v_n*3) $(1/3:%.3f) $(2^10:%e) $(max(1,(2+3)))\n"
           "cmd \"${name}\" '$n' x${name}y\n"
           "variable s string \"a b\"\n"
           "cmd ${s}\n"
           "variable dollar string '$n'\n"
           "cmd ${dollar}\n"
           "${name} $(step)\n");
  CHECK_EQ(r.commands.size(), std::size_t{5});
  if (r.commands.size() != 5) return;
  CHECK(r.commands[0].args ==
        args({"7", "box", "0.333333333333333", "14", "21", "0.333", "1.024000e+03", "5"}));
  // Quoted words keep their references; substitution inside a word splices text.
  CHECK(r.commands[1].args == args({"${name}", "$n", "xboxy"}));
  // A substituted value with a blank becomes two words.
  CHECK(r.commands[2].args == args({"a", "b"}));
  // Substituted text is not scanned again.
  CHECK(r.commands[3].args == args({"$n"}));
  CHECK_EQ(r.commands[4].name, std::string("box"));
  CHECK(r.commands[4].args == args({"0"}));
}

TEST_CASE("deck: equal-style variables are evaluated when read") {
  Recorder r;
  r.on_execute = [&](const Command& c) {
    if (c.name == "run") r.ctx.step += std::stod(c.args.at(0));
  };
  Variables vars;
  run_deck(r, vars,
           "variable t equal step*dt\n"
           "cmd ${t}\n"
           "run 200\n"
           "cmd ${t}\n"
           "variable t equal step\n"
           "cmd $t\n");
  CHECK_EQ(r.commands.size(), std::size_t{4});
  if (r.commands.size() != 4) return;
  CHECK(r.commands[0].args == args({"0"}));
  CHECK(r.commands[2].args == args({"0.002"}));
  CHECK(r.commands[3].args == args({"200"}));
}

TEST_CASE("deck: command-line -var takes precedence over the deck") {
  Recorder r;
  Variables vars;
  vars.define_from_command_line("T", {"300"});
  run_deck(r, vars,
           "variable T index 100\n"
           "variable P index 5\n"
           "variable P index 6\n"
           "cmd $T $P\n");
  CHECK_EQ(r.commands.size(), std::size_t{1});
  if (r.commands.size() == 1) CHECK(r.commands[0].args == args({"300", "5"}));

  Recorder r2;
  Variables vars2;
  vars2.define_from_command_line("T", {"300"});
  try {
    run_deck(r2, vars2, "cmd\nvariable T string 100\n");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK_EQ(e.where().line, 2);
    CHECK_EQ(e.command(), std::string("variable"));
    CHECK(contains(e.reason(), "-var"));
  }
}

TEST_CASE("deck: include resolves against the working directory") {
  TempDir dir;
  const WorkingDirectory cwd(dir.path());
  dir.write("main.in", "cmd before\ninclude sub.in\ncmd after ${fromsub}\n");
  dir.write("sub.in", "variable fromsub string yes\n\ncmd &\n  inside\n");
  Recorder r;
  Variables vars;
  Input input(r, vars);
  input.run_file("main.in");
  CHECK_EQ(r.commands.size(), std::size_t{3});
  if (r.commands.size() != 3) return;
  CHECK_EQ(r.commands[0].where.file, std::string("main.in"));
  CHECK_EQ(r.commands[1].where.file, std::string("sub.in"));
  CHECK_EQ(r.commands[1].where.line, 3);
  CHECK(r.commands[1].args == args({"inside"}));
  CHECK_EQ(r.commands[2].where.line, 3);
  CHECK(r.commands[2].args == args({"after", "yes"}));
}

TEST_CASE("deck: include errors carry the right location") {
  TempDir dir;
  const WorkingDirectory cwd(dir.path());
  Recorder r;
  Variables vars;
  Input input(r, vars);

  dir.write("missing.in", "cmd a\n\ninclude nowhere.in\n");
  try {
    input.run_file("missing.in");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK_EQ(e.where().file, std::string("missing.in"));
    CHECK_EQ(e.where().line, 3);
    CHECK_EQ(e.command(), std::string("include"));
    CHECK(contains(e.reason(), "nowhere.in"));
    CHECK_EQ(std::string(e.what()),
             std::string("missing.in:3: include: cannot open file 'nowhere.in'"));
  }

  dir.write("outer.in", "cmd a\ninclude inner.in\n");
  dir.write("inner.in", "cmd b\ncmd ${undefined_thing}\n");
  try {
    input.run_file("outer.in");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK_EQ(e.where().file, std::string("inner.in"));
    CHECK_EQ(e.where().line, 2);
    CHECK(contains(e.reason(), "undefined_thing"));
  }

  dir.write("self.in", "cmd loop\ninclude self.in\n");
  try {
    input.run_file("self.in");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK_EQ(e.where().file, std::string("self.in"));
    CHECK_EQ(e.where().line, 2);
    CHECK(contains(e.reason(), "nested deeper"));
  }

  try {
    input.run_file("no_such_deck.in");
    CHECK(false);
  } catch (const DeckError& e) {
    CHECK_EQ(e.where().file, std::string("no_such_deck.in"));
    CHECK(contains(e.what(), "cannot open"));
  }
}

TEST_CASE("deck: loops with label, jump and next") {
  Recorder r;
  Variables vars;
  run_deck(r, vars,
           "variable i loop 3\n"
           "label top\n"
           "cmd $i\n"
           "next i\n"
           "jump SELF top\n"
           "variable w index alpha beta\n"
           "label again\n"
           "cmd $w\n"
           "next w\n"
           "jump SELF again\n"
           "variable k loop 8 10 pad\n"
           "label padded\n"
           "cmd $k\n"
           "next k\n"
           "jump SELF padded\n"
           "cmd done\n");
  std::vector<std::string> seen;
  for (const Command& c : r.commands) seen.push_back(c.args.empty() ? c.name : c.args[0]);
  CHECK(seen == args({"1", "2", "3", "alpha", "beta", "08", "09", "10", "done"}));
  CHECK(!vars.exists("i"));  // exhausted loop variables are deleted
  if (r.commands.size() == 9) CHECK_EQ(r.commands[1].where.line, 3);
}

TEST_CASE("deck: nested loops") {
  Recorder r;
  Variables vars;
  run_deck(r, vars,
           "variable a loop 2\n"
           "label outer\n"
           "variable b loop 3\n"
           "label inner\n"
           "cmd $a $b\n"
           "next b\n"
           "jump SELF inner\n"
           "next a\n"
           "jump SELF outer\n");
  std::vector<std::string> seen;
  for (const Command& c : r.commands) seen.push_back(c.args.at(0) + c.args.at(1));
  CHECK(seen == args({"11", "12", "13", "21", "22", "23"}));
}

TEST_CASE("deck: jump errors") {
  const auto missing = deck_error("variable i loop 2\ncmd\njump SELF nowhere\n");
  CHECK(missing.has_value());
  if (missing) {
    CHECK_EQ(missing->where().line, 3);
    CHECK_EQ(missing->command(), std::string("jump"));
    CHECK(contains(missing->reason(), "nowhere"));
  }
  const auto other_file = deck_error("jump other.in\n");
  CHECK(other_file.has_value() && other_file->where().line == 1);

  Recorder r;
  Variables vars;
  Input input(r, vars);
  CHECK_THROWS_AS(input.run_line("jump SELF top", SourceLocation{"<line>", 4}), DeckError);
}

TEST_CASE("deck: print substitutes its text at execution") {
  TempDir dir;
  const WorkingDirectory cwd(dir.path());
  Recorder r;
  r.on_execute = [&](const Command& c) {
    if (c.name == "run") r.ctx.step += std::stod(c.args.at(0));
  };
  Variables vars;
  Input input(r, vars);
  dir.write("print.in",
            "variable x equal step*2\n"
            "print \"step is $(step) and x=${x}\"\n"
            "run 5\n"
            "print \"x=${x}\" file out.txt\n"
            "run 5\n"
            "print 'x=${x}' append out.txt screen no\n"
            "print plain\n"
            "print \"\"\"two\n"
            "lines $x\"\"\"\n");
  input.run_file("print.in");
  CHECK(r.messages == args({"step is 0 and x=0", "x=10", "plain", "two\nlines 20"}));
  CHECK_EQ(read_text(dir.path() / "out.txt"), std::string("x=10\nx=20\n"));

  const auto bad = deck_error("cmd\nprint \"a\" screen maybe\n");
  CHECK(bad.has_value() && bad->where().line == 2 && bad->command() == "print");
  const auto words = deck_error("print hello world\n");
  CHECK(words.has_value() && contains(words->reason(), "world"));
}

TEST_CASE("deck: echo and log") {
  Recorder r;
  Variables vars;
  run_deck(r, vars,
           "echo screen\n"
           "cmd a\n"
           "echo none\n"
           "cmd b\n"
           "log out.log append\n"
           "log other.log\n");
  CHECK(r.messages == args({"cmd a", "echo none"}));
  CHECK_EQ(r.logs.size(), std::size_t{2});
  if (r.logs.size() == 2) {
    CHECK(r.logs[0] == std::make_pair(std::string("out.log"), true));
    CHECK(r.logs[1] == std::make_pair(std::string("other.log"), false));
  }
  CHECK(deck_error("echo loud\n").has_value());
  CHECK(deck_error("log a.log b\n").has_value());
}

TEST_CASE("deck: handler exceptions become located DeckErrors") {
  Recorder r;
  r.on_execute = [](const Command& c) {
    if (c.name == "boom") throw EngineError("bad value");
    if (c.name == "crash") throw std::runtime_error("std failure");
    if (c.name == "located") throw DeckError(SourceLocation{"elsewhere", 77}, "x", "inner");
  };
  Variables vars;
  const auto boom = deck_error("cmd\nboom 1 2\n", &r);
  CHECK(boom.has_value());
  if (boom) {
    CHECK_EQ(boom->where().line, 2);
    CHECK_EQ(boom->command(), std::string("boom"));
    CHECK_EQ(boom->reason(), std::string("bad value"));
    CHECK(contains(boom->what(), "deck.in:2: boom: bad value"));
  }
  const auto crash = deck_error("\n\ncrash\n", &r);
  CHECK(crash.has_value() && crash->where().line == 3 && crash->reason() == "std failure");
  const auto located = deck_error("located\n", &r);
  CHECK(located.has_value() && located->where().file == "elsewhere" &&
        located->where().line == 77);
}

TEST_CASE("deck: run_line inside a command restores the location") {
  Recorder r;
  Variables vars;
  Input input(r, vars);
  std::vector<int> lines_seen;
  r.on_execute = [&](const Command& c) {
    if (c.name != "run") return;
    lines_seen.push_back(input.current().line);
    input.run_line("inner $i # comment", SourceLocation{"<every>", 99});
    lines_seen.push_back(input.current().line);
    input.run_line("", SourceLocation{"<every>", 100});
  };
  TempDir dir;
  input.run_file(dir.write("run.in", "variable i string 5\n\nrun 10 every 2 \"inner $i\"\n"));
  CHECK(lines_seen == std::vector<int>({3, 3}));
  CHECK_EQ(r.commands.size(), std::size_t{2});
  if (r.commands.size() == 2) {
    CHECK(r.commands[0].args == args({"10", "every", "2", "inner $i"}));
    CHECK_EQ(r.commands[1].name, std::string("inner"));
    CHECK(r.commands[1].args == args({"5"}));
    CHECK_EQ(r.commands[1].where.file, std::string("<every>"));
    CHECK_EQ(r.commands[1].where.line, 99);
  }
}

TEST_CASE("deck: substitute replaces references inside quotes too") {
  Recorder r;
  Variables vars;
  vars.define(args({"v", "equal", "1.5*2"}));
  Input input(r, vars);
  CHECK_EQ(input.substitute("a ${v} \"$v\" $(1+1) $(v_v/4:%.2f)"),
           std::string("a 3 \"3\" 2 0.75"));
  CHECK_THROWS_AS(input.substitute("${missing}"), EngineError);
}

TEST_CASE("deck: error paths report the right line") {
  struct Case {
    const char* deck;
    int line;
    const char* command;
    const char* reason_part;
  };
  const Case cases[] = {
      {"cmd a\ncmd b &\n", 2, "cmd", "'&' at end of file"},
      {"cmd a\ncmd b &", 2, "cmd", "'&' at end of file"},
      {"cmd a\n\ncmd \"abc\n", 3, "cmd", "unterminated quote"},
      {"cmd a\ncmd 'abc\ncmd c\n", 2, "cmd", "unterminated quote"},
      {"cmd a\nprint \"\"\"abc\nmore\n", 2, "print", "triple quote"},
      {"cmd\ncmd ${nope}\n", 2, "cmd", "'nope'"},
      {"cmd $q\n", 1, "cmd", "'q'"},
      {"cmd ${open\n", 1, "cmd", "missing '}'"},
      {"cmd $(1+2\n", 1, "cmd", "missing ')'"},
      {"cmd $\n", 1, "cmd", "'$'"},
      {"variable a equal 1.2.3\ncmd\ncmd ${a}\n", 3, "cmd", "'1.2.3'"},
      {"cmd $(2e)\n", 1, "cmd", "'2e'"},
      {"cmd\ncmd $(foo(2))\n", 2, "cmd", "unknown function 'foo'"},
      {"cmd $(1/0)\n", 1, "cmd", "division by zero"},
      {"cmd $(1:%d)\n", 1, "cmd", "%d"},
      {"cmd\nshell rm -rf /\n", 2, "shell", "refused"},
      {"variable\n", 1, "variable", "NAME"},
      {"variable x loop 0\n", 1, "variable", "at least 1"},
      {"variable x loop a\n", 1, "variable", "'a'"},
      {"variable x atom 1\n", 1, "variable", "'atom'"},
      {"variable x equal 1 + 2\n", 1, "variable", "one word"},
      {"variable x string a\nnext x\n", 2, "next", "string"},
      {"next y\n", 1, "next", "'y'"},
      {"label\n", 1, "label", "label NAME"},
      {"include\n", 1, "include", "include FILE"},
      {"print\n", 1, "print", "print TEXT"},
  };
  for (const Case& c : cases) {
    const auto error = deck_error(c.deck);
    CHECK(error.has_value());
    if (!error) {
      std::fprintf(stderr, "  no error for deck: %s\n", c.deck);
      continue;
    }
    const bool ok = error->where().line == c.line && error->command() == c.command &&
                    contains(error->reason(), c.reason_part);
    CHECK(ok);
    if (!ok) std::fprintf(stderr, "  deck %s -> %s\n", c.deck, error->what());
  }
}

// ---------------------------------------------------------------------------------------------
// Variables
// ---------------------------------------------------------------------------------------------

TEST_CASE("vars: styles, redefinition and next") {
  const FakeContext ctx;
  Variables vars;
  vars.define(args({"a", "index", "x", "y"}));
  vars.define(args({"a", "index", "ignored"}));  // redefining an index variable is ignored
  CHECK_EQ(vars.text("a", ctx), std::string("x"));
  CHECK(vars.style("a") == Variables::Style::Index);
  CHECK(vars.next({"a"}));
  CHECK_EQ(vars.text("a", ctx), std::string("y"));
  CHECK(!vars.next({"a"}));
  CHECK(!vars.exists("a"));

  vars.define(args({"s", "string", "one"}));
  vars.define(args({"s", "string", "two"}));  // string variables are replaced
  CHECK_EQ(vars.text("s", ctx), std::string("two"));
  CHECK_THROWS_AS(vars.define(args({"s", "equal", "1"})), EngineError);
  CHECK_THROWS_AS(vars.number("s", ctx), EngineError);
  vars.define(args({"s", "delete"}));
  CHECK(!vars.exists("s"));
  vars.define(args({"s", "delete"}));  // deleting an absent variable is allowed

  vars.define(args({"e", "equal", "atoms/4"}));
  CHECK_EQ(vars.number("e", ctx), 300.0);
  vars.define(args({"e", "equal", "atoms/3"}));
  CHECK_EQ(vars.text("e", ctx), std::string("400"));
  CHECK(vars.style("e") == Variables::Style::Equal);

  vars.define(args({"l", "loop", "2", "3"}));
  vars.define(args({"m", "loop", "5"}));
  CHECK_EQ(vars.number("l", ctx), 2.0);
  CHECK(vars.next({"l", "m"}));
  CHECK_EQ(vars.text("l", ctx), std::string("3"));
  CHECK_EQ(vars.text("m", ctx), std::string("2"));
  CHECK(!vars.next({"l", "m"}));  // l is exhausted and deleted, m goes on
  CHECK(!vars.exists("l"));
  CHECK_EQ(vars.text("m", ctx), std::string("3"));

  vars.define(args({"big", "loop", "1", "1000000000000"}));  // values are generated lazily
  CHECK(vars.next({"big"}));
  CHECK_EQ(vars.text("big", ctx), std::string("2"));

  CHECK_THROWS_AS(vars.next({"e"}), EngineError);
  CHECK_THROWS_AS(vars.next({"m", "big", "e"}), EngineError);
  CHECK_THROWS_AS(vars.define(args({"bad-name", "string", "x"})), EngineError);
  CHECK_THROWS_AS(vars.define(args({"l", "loop", "5", "2"})), EngineError);
  CHECK_THROWS_AS(vars.define(args({"x", "index"})), EngineError);
  CHECK_THROWS_AS(vars.text("nothing", ctx), EngineError);
  CHECK_THROWS_AS(vars.define_from_command_line("x", {}), EngineError);
}

TEST_CASE("vars: index values used as numbers") {
  const FakeContext ctx;
  Variables vars;
  vars.define_from_command_line("mu", {"0.35"});
  vars.define(args({"word", "index", "3abc"}));
  CHECK_EQ(vars.number("mu", ctx), 0.35);
  CHECK_EQ(dem::evaluate_expression("v_mu*2", vars, ctx), 0.7);
  CHECK_THROWS_AS(vars.number("word", ctx), EngineError);
}

// ---------------------------------------------------------------------------------------------
// Equal-style formulas
// ---------------------------------------------------------------------------------------------

TEST_CASE("expr: numbers and operator precedence") {
  CHECK_EQ(eval("1+2*3"), 7.0);
  CHECK_EQ(eval("(1+2)*3"), 9.0);
  CHECK_EQ(eval("7-2-1"), 4.0);
  CHECK_EQ(eval("8/2/2"), 2.0);
  CHECK_EQ(eval("2^3^2"), 64.0);  // left to right, as LAMMPS
  CHECK_EQ(eval("-2^2"), 4.0);     // unary minus binds tighter than ^ (LAMMPS)
  CHECK_EQ(eval("-(2^2)"), -4.0);
  CHECK_EQ(eval("2^-1"), 0.5);
  CHECK_EQ(eval("2*3^2"), 18.0);
  CHECK_EQ(eval("10%3"), 1.0);
  CHECK_EQ(eval("-7%3"), -1.0);
  CHECK_EQ(eval("1+10%4*2"), 5.0);
  CHECK_EQ(eval("1e-6*1e6"), 1.0);
  CHECK_EQ(eval(".5+.25"), 0.75);
  CHECK_EQ(eval("1.5E+2"), 150.0);
  CHECK_EQ(eval("3."), 3.0);
  CHECK_EQ(eval(" 2 * ( 3 + 4 ) "), 14.0);
  CHECK_EQ(eval("--3"), 3.0);
  CHECK_EQ(eval("1<2"), 1.0);
  CHECK_EQ(eval("2<=1"), 0.0);
  CHECK_EQ(eval("2>=2"), 1.0);
  CHECK_EQ(eval("3>4"), 0.0);
  CHECK_EQ(eval("1+1==2"), 1.0);
  CHECK_EQ(eval("1<2==1"), 1.0);
  CHECK_EQ(eval("2!=2"), 0.0);
  CHECK_EQ(eval("1==1 && 0"), 0.0);
  CHECK_EQ(eval("0 || 3>2"), 1.0);
  CHECK_EQ(eval("1 || 0 && 0"), 1.0);  // && before ||
  CHECK_EQ(eval("!0"), 1.0);
  CHECK_EQ(eval("!5"), 0.0);
  CHECK_EQ(eval("!0+1"), 2.0);
  CHECK_EQ(eval("PI"), kPi);
}

TEST_CASE("expr: math functions") {
  CHECK_EQ(eval("sqrt(16)"), 4.0);
  CHECK_EQ(eval("exp(0)"), 1.0);
  CHECK_NEAR(eval("ln(exp(2))"), 2.0, 1e-15);
  CHECK_NEAR(eval("log(1000)"), 3.0, 1e-15);
  CHECK_EQ(eval("abs(-3.5)"), 3.5);
  CHECK_NEAR(eval("sin(PI/2)"), 1.0, 1e-15);
  CHECK_EQ(eval("cos(0)"), 1.0);
  CHECK_NEAR(eval("tan(PI/4)"), 1.0, 1e-15);
  CHECK_NEAR(eval("asin(1)"), kPi / 2.0, 1e-15);
  CHECK_EQ(eval("acos(1)"), 0.0);
  CHECK_NEAR(eval("atan(1)"), kPi / 4.0, 1e-15);
  CHECK_NEAR(eval("atan2(1,-1)"), 3.0 * kPi / 4.0, 1e-15);
  CHECK_EQ(eval("ceil(1.2)"), 2.0);
  CHECK_EQ(eval("floor(-1.2)"), -2.0);
  CHECK_EQ(eval("round(2.5)"), 3.0);
  CHECK_EQ(eval("round(-2.5)"), -3.0);
  CHECK_EQ(eval("min(3,-1)"), -1.0);
  CHECK_EQ(eval("max(3, -1)"), 3.0);
  CHECK_EQ(eval("max(1,min(5,2))*2"), 4.0);
  CHECK_EQ(eval("sqrt(2^2+(1+1)^2*3)"), 4.0);
}

TEST_CASE("expr: simulation values and variables") {
  FakeContext ctx;
  ctx.step = 100.0;
  Variables vars;
  vars.define(args({"a", "equal", "v_b*2"}));
  vars.define(args({"b", "equal", "step+1"}));
  vars.define(args({"n", "index", "4"}));
  const auto ev = [&](const std::string& f) { return dem::evaluate_expression(f, vars, ctx); };
  CHECK_EQ(ev("v_a+v_n"), 206.0);
  CHECK_EQ(ev("step*dt"), 1e-3);
  CHECK_EQ(ev("ke"), 0.25);         // thermo keyword
  CHECK_EQ(ev("ke(all)"), 2.0);     // group function of the same name
  CHECK_EQ(ev("count(top)"), 21.0);
  CHECK_EQ(ev("mass(all)*2"), 1.5);
  CHECK_EQ(ev("xcm(top,z)"), 0.125);
  CHECK_EQ(ev("vcm( all , y )"), -0.5);
  CHECK_EQ(ev("bound(all,zmax)-bound(all,zmin)"), 0.06);
  CHECK_EQ(ev("c_press"), 100.0);
  CHECK_EQ(ev("c_press[2]"), 102.0);
  CHECK_EQ(ev("f_wall[3]/f_wall"), 31.0);
  CHECK_EQ(ev("count(all,box)+xcm(all,z,box)"), 42.125);  // trailing region argument
  const std::vector<std::string> expected_calls = {
      "ke(all)",    "count(top)",      "mass(all)",       "xcm(top,z)",    "vcm(all,y)",
      "bound(all,zmax)", "bound(all,zmin)", "count(all,box)", "xcm(all,z,box)"};
  CHECK(ctx.calls == expected_calls);
}

TEST_CASE("expr: errors name the offending token") {
  Variables cycle;
  cycle.define(args({"p", "equal", "v_q+1"}));
  cycle.define(args({"q", "equal", "v_p+1"}));
  struct Case {
    const char* formula;
    const char* part;
  };
  const Case cases[] = {
      {"1/0", "division by zero in formula '1/0'"},
      {"5%0", "modulo by zero"},
      {"sqrt(-1)", "sqrt"},
      {"ln(0)", "ln"},
      {"log(-2)", "log"},
      {"asin(2)", "asin"},
      {"acos(-1.5)", "acos"},
      {"0^-1", "zero"},
      {"(-8)^(1/3)", "non-integer"},
      {"foo(1)", "unknown function 'foo'"},
      {"1.2.3", "bad number '1.2.3'"},
      {"2e", "bad number '2e'"},
      {"3abc", "bad number '3abc'"},
      {"unknownkw*2", "unknown name 'unknownkw'"},
      {"(1+2", "missing ')'"},
      {"1+", "value is expected"},
      {"1 2", "unexpected '2'"},
      {"", "empty formula"},
      {"2 = 2", "unexpected '='"},
      {"1 & 1", "unexpected '&'"},
      {"v_nope", "undefined variable 'v_nope'"},
      {"v_p", "circular"},
      {"c_press[0]", "bad index"},
      {"c_press[x]", "bad index"},
      {"c_nope", "unknown compute 'nope'"},
      {"f_nope[2]", "unknown fix 'nope'"},
      {"xcm(all)", "takes 2 or 3 arguments"},
      {"count(all,box,x)", "takes 1 or 2 arguments"},
      {"xcm(all,w)", "dimension"},
      {"bound(all,top)", "direction"},
      {"count(nogroup)", "unknown group 'nogroup'"},
      {"count(1+2)", "not formulas"},
      {"count(all", "missing ')'"},
      {"atan2(1)", "takes 2 arguments"},
      {"sqrt()", "takes 1 argument"},
      {"sqrt(1,2)", "takes 1 argument"},
      {"+1", "unexpected '+1'"},
      {"v_x[1]", "vector"},
  };
  for (const Case& c : cases) {
    const std::string message = eval_error(c.formula, cycle);
    const bool ok = contains(message, c.part);
    CHECK(ok);
    if (!ok) std::fprintf(stderr, "  formula '%s' -> '%s'\n", c.formula, message.c_str());
  }
  // Deep nesting is refused instead of exhausting the stack.
  CHECK(contains(eval_error(std::string(5000, '(') + "1" + std::string(5000, ')')),
                 "nested too deeply"));
  CHECK(contains(eval_error(std::string(5000, '-') + "1"), "nested too deeply"));
  CHECK_EQ(eval(std::string(100, '(') + "1" + std::string(100, ')')), 1.0);
}

// ---------------------------------------------------------------------------------------------
// Robustness
// ---------------------------------------------------------------------------------------------

TEST_CASE("deck: fuzzed decks only ever raise DeckError") {
  TempDir dir;
  const WorkingDirectory cwd(dir.path());
  dir.write("part.in", "cmd in_part $(1+2)\n");
  const std::string base =
      "variable n loop 3\n"
      "variable s string \"a b\"\n"
      "variable f equal 2*v_n+1\n"
      "label top\n"
      "cmd ${n} $s ${f} $(v_f/2:%.2f) \"quoted # text\" 'single'\n"
      "print \"n=${n} f=${f} $(sqrt(v_f)+count(all))\"\n"
      "fix 1 all &\n"
      "   nve\n"
      "next n\n"
      "jump SELF top\n"
      "include part.in\n"
      "print \"\"\"triple\n"
      "line\"\"\" screen no\n"
      "cmd done # end\n";

  // A handler that stops any runaway loop by failing after a fixed number of calls.
  class BudgetHandler : public Recorder {
   public:
    int calls = 0;
    void execute(const Command& command) override {
      if (++calls > 200) throw EngineError("call budget used up");
      Recorder::execute(command);
    }
    void message(const std::string& text) override {
      if (++calls > 200) throw EngineError("call budget used up");
      Recorder::message(text);
    }
  };

  const std::string alphabet = "$${}()\"'#&\n :%_v.,[]0123456789abcSELF +-*/^!<>=";
  std::mt19937 rng(20240611u);
  int deck_errors = 0;
  int clean_runs = 0;
  int other_failures = 0;
  for (int iteration = 0; iteration < 3000; ++iteration) {
    std::string deck = base;
    const int mutations = 1 + static_cast<int>(rng() % 3);
    for (int m = 0; m < mutations; ++m) {
      const std::size_t pos = deck.empty() ? 0 : rng() % (deck.size() + 1);
      switch (rng() % 5) {
        case 0:
        case 1:
          deck.insert(pos, 1, alphabet[rng() % alphabet.size()]);
          break;
        case 2:
        case 3:
          if (pos < deck.size()) deck.erase(pos, 1);
          break;
        default:
          deck.resize(pos);
          break;
      }
    }
    BudgetHandler handler;
    Variables vars;
    Input input(handler, vars);
    try {
      input.run_file(dir.write("fuzz.in", deck));
      ++clean_runs;
    } catch (const DeckError& e) {
      ++deck_errors;
      // Every error points into a deck file at a real line.
      CHECK(e.where().line >= 1);
    } catch (const std::exception& e) {
      ++other_failures;
      std::fprintf(stderr, "  fuzz iteration %d escaped with: %s\n", iteration, e.what());
    }
  }
  CHECK_EQ(other_failures, 0);
  // The mutations exercise both outcomes.
  CHECK(deck_errors > 300);
  CHECK(clean_runs > 300);
}
