// A minimal writer of one-line JSON objects whose keys keep the order they were added in (jsoncpp sorts keys,
// which makes log lines harder to read). Keys are program constants and are not escaped.
#pragma once

#include <string>
#include <vector>

namespace arcsim {

class JsonLine {
 public:
  // Shortest decimal form that reads back as the same double; null if not finite (JSON has no NaN/inf).
  JsonLine& number(const char* key, double x);
  JsonLine& integer(const char* key, long long x);
  JsonLine& boolean(const char* key, bool b);
  JsonLine& object(const char* key, const JsonLine& inner);
  // A string value, escaped (quotes, backslashes and control characters).
  JsonLine& text(const char* key, const std::string& value);
  // Arrays of numbers (as number()), of integers, and of objects.
  JsonLine& numbers(const char* key, const std::vector<double>& values);
  JsonLine& integers(const char* key, const std::vector<long long>& values);
  JsonLine& objects(const char* key, const std::vector<JsonLine>& values);
  std::string str() const { return "{" + body_ + "}"; }

 private:
  void key(const char* name);
  std::string body_;
};

// The number as JSON text (see JsonLine::number).
std::string json_number(double x);

}  // namespace arcsim
