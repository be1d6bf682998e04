#include "app/json_line.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace arcsim {

std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  // printf's %.*g (to_chars with a precision writes exactly that), with the fewest digits from 6 on that read
  // back as x. to_chars/from_chars: snprintf and strtod cost ~3000 instructions a number, a tenth of a light
  // scene's frame output (log.jsonl lists every step's residual).
  char buffer[40];
  std::to_chars_result written{};
  for (int digits = 6; digits <= 17; ++digits) {
    written = std::to_chars(buffer, buffer + sizeof buffer, x, std::chars_format::general, digits);
    double back = 0;
    std::from_chars(buffer, written.ptr, back);
    if (back == x) break;
  }
  return std::string(buffer, written.ptr);
}

void JsonLine::key(const char* name) {
  if (!body_.empty()) body_ += ',';
  body_ += '"';
  body_ += name;
  body_ += "\":";
}

JsonLine& JsonLine::number(const char* name, double x) {
  key(name);
  body_ += json_number(x);
  return *this;
}

JsonLine& JsonLine::integer(const char* name, long long x) {
  key(name);
  body_ += std::to_string(x);
  return *this;
}

JsonLine& JsonLine::boolean(const char* name, bool b) {
  key(name);
  body_ += b ? "true" : "false";
  return *this;
}

JsonLine& JsonLine::object(const char* name, const JsonLine& inner) {
  key(name);
  body_ += inner.str();
  return *this;
}

JsonLine& JsonLine::text(const char* name, const std::string& value) {
  key(name);
  body_ += '"';
  for (unsigned char c : value) {
    if (c == '"' || c == '\\') {
      body_ += '\\';
      body_ += static_cast<char>(c);
    } else if (c < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      body_ += escaped;
    } else {
      body_ += static_cast<char>(c);
    }
  }
  body_ += '"';
  return *this;
}

JsonLine& JsonLine::numbers(const char* name, const std::vector<double>& values) {
  key(name);
  body_ += '[';
  for (size_t i = 0; i < values.size(); ++i) body_ += (i ? "," : "") + json_number(values[i]);
  body_ += ']';
  return *this;
}

JsonLine& JsonLine::integers(const char* name, const std::vector<long long>& values) {
  key(name);
  body_ += '[';
  for (size_t i = 0; i < values.size(); ++i) body_ += (i ? "," : "") + std::to_string(values[i]);
  body_ += ']';
  return *this;
}

JsonLine& JsonLine::objects(const char* name, const std::vector<JsonLine>& values) {
  key(name);
  body_ += '[';
  for (size_t i = 0; i < values.size(); ++i) body_ += (i ? "," : "") + values[i].str();
  body_ += ']';
  return *this;
}

}  // namespace arcsim
