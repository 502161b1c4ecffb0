#include "sim/io/text_fields.h"

#include <charconv>
#include <cmath>
#include <cstring>

namespace sim {

bool parse_finite_double(std::string_view tok, double* v) {
  const char* b = tok.data();
  const char* e = b + tok.size();
  if (b != e && *b == '+') ++b;
  if (b == e) return false;
  auto r = std::from_chars(b, e, *v);
  return r.ec == std::errc() && r.ptr == e && std::isfinite(*v);
}

bool FieldLines::next(std::size_t keep, std::vector<std::string_view>* fields) {
  while (p_ < end_) {
    const char* eol = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
    if (!eol) eol = end_;
    ++line_no_;
    const char* q = p_;
    p_ = eol + 1;
    fields->clear();
    while (q < eol && fields->size() <= keep) {
      while (q < eol && separator(*q)) ++q;
      if (q == eol) break;
      const char* b = q;
      while (q < eol && !separator(*q)) ++q;
      fields->emplace_back(b, static_cast<std::size_t>(q - b));
    }
    if (fields->empty() || (*fields)[0][0] == '#') continue;
    return true;
  }
  return false;
}

}  // namespace sim
