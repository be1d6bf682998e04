// The plastic work of a frame in log.jsonl (app/frame_report): present, per cloth and in total, only when the
// report carries it.
#include <gtest/gtest.h>
#include <json/json.h>

#include <memory>
#include <string>

#include "app/frame_report.hpp"

namespace arcsim {
namespace {

Json::Value parse(const std::string& line) {
  Json::CharReaderBuilder builder;
  std::unique_ptr<Json::CharReader> reader(builder.newCharReader());
  Json::Value v;
  std::string errors;
  EXPECT_TRUE(reader->parse(line.data(), line.data() + line.size(), &v, &errors)) << errors;
  return v;
}

TEST(PlasticWorkLog, TotalAndPerClothWorkInTheFrameLine) {
  FrameReport r;
  r.frame = 3;
  r.plastic_work = {1.5, 0.25};
  const Json::Value v = parse(frame_log_line(r));
  EXPECT_EQ(v["plastic_work"]["total"].asDouble(), 1.75);
  EXPECT_EQ(v["plastic_work"]["cloth0"].asDouble(), 1.5);
  EXPECT_EQ(v["plastic_work"]["cloth1"].asDouble(), 0.25);
  EXPECT_EQ(v["frame"].asInt(), 3);
}

TEST(PlasticWorkLog, AbsentWithoutPlasticity) {
  FrameReport r;
  EXPECT_FALSE(parse(frame_log_line(r)).isMember("plastic_work"));
}

}  // namespace
}  // namespace arcsim
