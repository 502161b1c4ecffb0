// Field-per-line text files (Freiburg relations, corrected poses, trajectories): one reader of
// lines split on separators, shared by sim/io's parsers so that each says only what its fields mean.
#pragma once

#include <cstddef>
#include <string_view>
#include <vector>

namespace sim {

// The whole token as a finite double (strtod syntax minus hex; a leading '+' is accepted).
bool parse_finite_double(std::string_view tok, double* v);

// Walks `data` line by line. next() returns the next line that has a field and does not start with
// '#', split on blanks (' ', '\t', '\r'; also ',' with commas = true); at most `keep` + 1 fields are
// kept, so a caller expecting `keep` can say "more" without a huge line costing a huge list.
class FieldLines {
 public:
  explicit FieldLines(std::string_view data, bool commas = false) : p_(data.data()), end_(p_ + data.size()), commas_(commas) {}
  bool next(std::size_t keep, std::vector<std::string_view>* fields);
  std::size_t line_no() const { return line_no_; }  // 1-based number of the line next() returned

 private:
  bool separator(char c) const { return c == ' ' || c == '\t' || c == '\r' || (commas_ && c == ','); }
  const char* p_;
  const char* end_;
  bool commas_;
  std::size_t line_no_ = 0;
};

}  // namespace sim
