// Function length, checked (issue 34): no function of the product (engine/src, gi/src, tools,
// game_demo/src; tests, fuzz targets and benchmarks aside) over kMaxLines lines from its
// opening brace to its closing one. The functions that were longer when the rule came are
// listed in long_functions.txt with their length then: they may shrink, never grow, and a
// function not listed may not pass the limit. Splitting one removes its line.
//
// The second rule: a function of the product over kExplainLines (60) lines says why at its top,
// in a comment line that starts with "Long because" (after the "//"), either in the comment
// block right above its head or in the first lines of its body, for example
//   // Long because it is one sequence: parse, load, bake, write; each step's failure returns
//   // its exit code, and split up the steps would pass the same dozen options around.
//   int main(int argc, char** argv) {
// The reason says what the function does in one sequence and why splitting it would hurt;
// where no honest reason exists, split the function instead. There is no allowlist: every
// function over 60 lines carries its reason.
//
// The parser is deliberately small: comments, string and character literals are blanked, then
// braces are matched; a brace opens a function body when it follows a parenthesised list at
// namespace or class scope (constructors with initialiser lists included), and opens a scope
// when it follows namespace, class, struct, union, enum or extern. Lambdas and local blocks
// count towards the function they are in.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

constexpr int kMaxLines = 100;
constexpr int kExplainLines = 60;
// How far into its body a function's reason may start (lines after the opening brace's).
constexpr int kReasonBodyLines = 3;

struct Function {
  std::string file;  // relative to the source root
  std::string name;
  int first_line = 0;  // the opening brace's
  int lines = 0;
  int head_line = 0;  // where the head (return type, name, parameters) begins
};

// The text with comments, string and character literals replaced by spaces (newlines kept).
std::string blank_comments_and_literals(const std::string& in) {
  std::string out = in;
  enum { Code, Line, Block, Str, Chr, Raw } st = Code;
  std::string raw_end;
  bool at_line_start = true;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const char c = in[i];
    const char n = i + 1 < in.size() ? in[i + 1] : '\0';
    const bool line_start = at_line_start;
    at_line_start = c == '\n' || (line_start && (c == ' ' || c == '\t'));
    if (st != Code) at_line_start = c == '\n';
    switch (st) {
      case Code:
        if (c == '#' && line_start) {  // a preprocessor line, continuations included
          while (i < in.size() && !(in[i] == '\n' && in[i - 1] != '\\')) {
            out[i] = ' ';
            ++i;
          }
          at_line_start = true;
          break;
        }
        if (c == '/' && n == '/') {
          st = Line;
          out[i] = ' ';
        } else if (c == '/' && n == '*') {
          st = Block;
          out[i] = ' ';
        } else if (c == 'R' && n == '"' && (i == 0 || !std::isalnum(static_cast<unsigned char>(in[i - 1])))) {
          const std::size_t open = in.find('(', i + 2);
          if (open == std::string::npos) break;
          raw_end = ")" + in.substr(i + 2, open - i - 2) + "\"";
          for (std::size_t k = i; k <= open; ++k)
            if (out[k] != '\n') out[k] = ' ';
          i = open;
          st = Raw;
        } else if (c == '"') {
          st = Str;
        } else if (c == '\'' && !(i > 0 && std::isxdigit(static_cast<unsigned char>(in[i - 1])) &&
                                  std::isxdigit(static_cast<unsigned char>(n)))) {  // not 1'000'000
          st = Chr;
        }
        break;
      case Line:
        if (c == '\n')
          st = Code;
        else
          out[i] = ' ';
        break;
      case Block:
        if (c == '*' && n == '/') {
          out[i] = out[i + 1] = ' ';
          ++i;
          st = Code;
        } else if (c != '\n') {
          out[i] = ' ';
        }
        break;
      case Str:
      case Chr:
        if (c == '\\') {
          out[i] = ' ';
          if (i + 1 < in.size() && in[i + 1] != '\n') out[++i] = ' ';
        } else if ((st == Str && c == '"') || (st == Chr && c == '\'')) {
          st = Code;
        } else if (c != '\n') {
          out[i] = ' ';
        }
        break;
      case Raw:
        if (in.compare(i, raw_end.size(), raw_end) == 0) {
          for (std::size_t k = i; k < i + raw_end.size() - 1; ++k) out[k] = ' ';
          i += raw_end.size() - 1;
          st = Code;
        } else if (c != '\n') {
          out[i] = ' ';
        }
        break;
    }
  }
  return out;
}

// The function definitions of `text` (already blanked) with their lengths in lines.
std::vector<Function> functions_of(const std::string& text, const std::string& file) {
  static const std::regex scope_head(R"(^\s*(template\s*<.*>\s*)?(namespace|class|struct|union|enum|extern)\b)");
  static const std::regex function_head(R"(([A-Za-z_~][A-Za-z_0-9:~<>]*|operator\s*[^\s(]+)\s*\([^;]*\)\s*[^;()]*$)");
  static const std::regex control_head(R"(^\s*(if|for|while|switch|catch|do|else|return)\b)");
  std::vector<Function> out;
  enum Kind { Scope, Body, Other };
  std::vector<Kind> stack;
  std::size_t head_start = 0;  // where the current statement's text began
  int line = 1;
  int body_depth = -1;  // stack depth of the function body being measured
  Function current;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (c == ';' || c == '}') {
      if (c == '}' && !stack.empty()) {
        if (static_cast<int>(stack.size()) - 1 == body_depth) {
          current.lines = line - current.first_line + 1;
          out.push_back(current);
          body_depth = -1;
        }
        stack.pop_back();
      }
      head_start = i + 1;
      continue;
    }
    if (c != '{') continue;
    std::string head = text.substr(head_start, i - head_start);
    std::replace(head.begin(), head.end(), '\n', ' ');
    // A brace initialiser in a constructor's list ("b_{y}"): skipped whole, the head goes on.
    if (body_depth < 0 && head.find(") :") != std::string::npos && i > 0 &&
        (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_' || text[i - 1] == '>')) {
      for (int depth = 0; i < text.size(); ++i) {
        if (text[i] == '\n') ++line;
        if (text[i] == '{') ++depth;
        if (text[i] == '}' && --depth == 0) break;
      }
      continue;
    }
    // The head outside parentheses: an '=' there is a variable's initialiser, not a body.
    std::string outside;
    for (int depth = 0; char h : head) {
      if (h == '(') ++depth;
      if (depth == 0) outside += h;
      if (h == ')') --depth;
    }
    static const std::regex assignment(R"([^=!<>]=[^=])");
    const bool initialiser = std::regex_search(outside, assignment) && outside.find("operator") == std::string::npos;
    const bool in_scope = std::all_of(stack.begin(), stack.end(), [](Kind k) { return k == Scope; });
    Kind kind = Other;
    if (in_scope && std::regex_search(head, scope_head) && head.find('(') == std::string::npos) {
      kind = Scope;
    } else if (in_scope && body_depth < 0 && !std::regex_search(head, control_head) && !initialiser) {
      // A body: "name(...) qualifiers {" or a constructor's "name(...) : a(x), b{y} {".
      const std::size_t colon = head.find(") :");
      const std::string sig = colon == std::string::npos ? head : head.substr(0, colon + 1);
      std::smatch m;
      if (std::regex_search(sig, m, function_head)) {
        kind = Body;
        current = {file, m[1].str(), line, 0, line};
        // The head's first line: count back the newlines between its first character and the brace.
        const std::size_t first = text.find_first_not_of(" \t\n", head_start);
        if (first != std::string::npos && first < i)
          current.head_line = line - static_cast<int>(std::count(text.begin() + static_cast<std::ptrdiff_t>(first),
                                                                 text.begin() + static_cast<std::ptrdiff_t>(i), '\n'));
        body_depth = static_cast<int>(stack.size());
      }
    }
    stack.push_back(kind);
    head_start = i + 1;
  }
  return out;
}

std::map<std::string, int> read_allowed() {
  std::map<std::string, int> allowed;
  std::ifstream in(fs::path(GI_SOURCE_DIR) / "tests" / "architecture" / "long_functions.txt");
  EXPECT_TRUE(in) << "cannot read tests/architecture/long_functions.txt";
  for (std::string l; std::getline(in, l);) {
    if (l.empty() || l[0] == '#') continue;
    std::istringstream words(l);
    int lines = 0;
    std::string where;
    words >> lines >> where;
    allowed[where] = lines;
  }
  return allowed;
}

// The product's sources: each file's lines as written, by path relative to the source root.
using SourceLines = std::map<std::string, std::vector<std::string>>;

std::vector<Function> product_functions(SourceLines* sources = nullptr) {
  std::vector<Function> all;
  const fs::path root(GI_SOURCE_DIR);
  for (const char* top : {"engine/src", "gi/src", "tools", "game_demo/src"}) {
    for (const auto& e : fs::recursive_directory_iterator(root / top)) {
      if (!e.is_regular_file() || e.path().extension() != ".cpp") continue;
      std::ifstream in(e.path());
      std::stringstream ss;
      ss << in.rdbuf();
      const std::string rel = fs::relative(e.path(), root).string();
      for (Function& f : functions_of(blank_comments_and_literals(ss.str()), rel)) all.push_back(std::move(f));
      if (sources) {
        std::vector<std::string>& lines = (*sources)[rel];
        std::istringstream text(ss.str());
        for (std::string l; std::getline(text, l);) lines.push_back(l);
      }
    }
  }
  return all;
}

// True when `line` is a // comment whose text starts with "Long because".
bool is_reason(const std::string& line) {
  static const std::regex reason(R"(^\s*//+\s*Long because\b)");
  return std::regex_search(line, reason);
}

// True when `f` says why it is long: a "Long because" line in the // comment block right above
// its head, or in the first kReasonBodyLines lines of its body.
bool explains_its_length(const Function& f, const std::vector<std::string>& lines) {
  static const std::regex comment(R"(^\s*//)");
  for (int l = f.head_line - 1; l >= 1 && std::regex_search(lines[static_cast<std::size_t>(l - 1)], comment); --l)
    if (is_reason(lines[static_cast<std::size_t>(l - 1)])) return true;
  for (int l = f.first_line; l <= f.first_line + kReasonBodyLines && l <= static_cast<int>(lines.size()); ++l)
    if (is_reason(lines[static_cast<std::size_t>(l - 1)])) return true;
  return false;
}

}  // namespace

TEST(FunctionLength, TheParserFindsBodiesNotScopesOrLambdas) {
  const std::string code =
      "namespace a {\n"
      "struct S {\n"
      "  int f(int x) const { return x; }\n"
      "};\n"
      "S::S(int v) : v_(v), w_{2} {\n"
      "  auto l = [](int q) { return q; };\n"
      "  const char* s = \"{ not a brace\"; // {\n"
      "}\n"
      "int g() {\n"
      "  if (x) {\n"
      "  }\n"
      "  return 0;\n"
      "}\n"
      "}  // namespace a\n";
  const std::vector<Function> f = functions_of(blank_comments_and_literals(code), "x.cpp");
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].name, "f");
  EXPECT_EQ(f[0].lines, 1);
  EXPECT_EQ(f[1].name, "S::S");
  EXPECT_EQ(f[1].lines, 4);
  EXPECT_EQ(f[2].name, "g");
  EXPECT_EQ(f[2].first_line, 9);
  EXPECT_EQ(f[2].lines, 5);
  EXPECT_EQ(f[2].head_line, 9);
}

TEST(FunctionLength, AReasonIsFoundAboveTheHeadOrAtTheTopOfTheBody) {
  const std::string code =
      "// Does one thing.\n"
      "// Long because the steps share the state below.\n"
      "template <class T>\n"
      "int above(T x,\n"
      "          T y) {\n"
      "  return 0;\n"
      "}\n"
      "int inside() {\n"
      "  // Long because it is one table.\n"
      "  return 0;\n"
      "}\n"
      "// Long because of nothing: a blank line parts this comment from the function.\n"
      "\n"
      "int parted() {\n"
      "  return 0;\n"
      "}\n"
      "int late() {\n"
      "  int a = 0;\n"
      "  int b = 0;\n"
      "  int c = 0;\n"
      "  // Long because this comes too late.\n"
      "  return a + b + c;\n"
      "}\n";
  const std::vector<Function> f = functions_of(blank_comments_and_literals(code), "x.cpp");
  std::vector<std::string> lines;
  std::istringstream text(code);
  for (std::string l; std::getline(text, l);) lines.push_back(l);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0].head_line, 3);
  EXPECT_TRUE(explains_its_length(f[0], lines));
  EXPECT_TRUE(explains_its_length(f[1], lines));
  EXPECT_FALSE(explains_its_length(f[2], lines));
  EXPECT_FALSE(explains_its_length(f[3], lines));
  EXPECT_FALSE(is_reason("  int long_because = 0;  // Long because"));
}

TEST(FunctionLength, NoFunctionOfTheProductGrowsPastTheLimit) {
  const std::map<std::string, int> allowed = read_allowed();
  const std::vector<Function> all = product_functions();
  ASSERT_GT(all.size(), 1000u) << "the parser found too few functions to be reading the sources";
  std::map<std::string, int> seen;
  for (const Function& f : all) {
    const std::string where = f.file + ":" + f.name;
    seen[where] = std::max(seen[where], f.lines);
    if (f.lines <= kMaxLines) continue;
    const auto it = allowed.find(where);
    if (it == allowed.end())
      ADD_FAILURE() << where << " (line " << f.first_line << ") is " << f.lines << " lines, over " << kMaxLines
                    << ": split it";
    else
      EXPECT_LE(f.lines, it->second) << where << " grew from " << it->second << " lines: split it instead";
  }
  int over = 0;
  for (const auto& [where, lines] : allowed) {
    const auto it = seen.find(where);
    if (it == seen.end() || it->second <= kMaxLines) {
      ADD_FAILURE() << where << " is listed in long_functions.txt but is now "
                    << (it == seen.end() ? "gone" : "within the limit") << ": remove its line";
    } else {
      ++over;
    }
  }
  std::printf("%zu functions read, %d over %d lines (listed, to be split)\n", all.size(), over, kMaxLines);
}

TEST(FunctionLength, EveryFunctionOverSixtyLinesSaysWhyAtItsTop) {
  SourceLines sources;
  const std::vector<Function> all = product_functions(&sources);
  int unexplained = 0;  // over the limit and without a reason
  int explained = 0;
  for (const Function& f : all) {
    if (f.lines <= kExplainLines) continue;
    const std::string where = f.file + ":" + f.name;
    if (explains_its_length(f, sources.at(f.file))) {
      ++explained;
      continue;
    }
    ++unexplained;
    ADD_FAILURE() << where << " (line " << f.first_line << ") is " << f.lines << " lines, over " << kExplainLines
                  << ", with no \"// Long because ...\" comment at its top: write why it cannot be split, or split it";
  }
  std::printf("%d functions over %d lines say why, %d do not\n", explained, kExplainLines, unexplained);
}
