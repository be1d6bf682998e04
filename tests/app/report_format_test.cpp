// The pieces of the simulate command that need no binary: JSON lines, output file names, durations.
#include <gtest/gtest.h>
#include <json/json.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "app/frame_report.hpp"
#include "app/json_line.hpp"
#include "app/output_files.hpp"
#include "app/progress.hpp"

namespace arcsim {
namespace {

Json::Value parse(const std::string& text) {
  Json::CharReaderBuilder builder;
  Json::Value root;
  std::string errors;
  std::istringstream in(text);
  EXPECT_TRUE(Json::parseFromStream(builder, in, &root, &errors)) << errors << " in " << text;
  return root;
}

TEST(JsonNumber, ShortestFormThatReadsBackExactly) {
  EXPECT_EQ(json_number(0.04), "0.04");
  EXPECT_EQ(json_number(3), "3");
  EXPECT_EQ(json_number(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(json_number(0.1 + 0.2), "0.30000000000000004");
  const double third = 1.0 / 3;
  EXPECT_EQ(std::stod(json_number(third)), third);
  EXPECT_EQ(json_number(std::nan("")), "null");
  EXPECT_EQ(json_number(-INFINITY), "null");
}

// The same text as printf's %.*g with the fewest digits from 6 on that strtod reads back exactly (the form the
// log always had), over magnitudes from denormals to 1e300, round numbers and integers included.
TEST(JsonNumber, SameTextAsPrintfsShortestRoundTrip) {
  auto reference = [](double x) {
    char buffer[40];
    for (int digits = 6; digits <= 17; ++digits) {
      std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
      if (std::strtod(buffer, nullptr) == x) break;
    }
    return std::string(buffer);
  };
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> mantissa(-10, 10);
  std::uniform_int_distribution<int> exponent(-320, 300);
  std::vector<double> values = {0.0, -0.0, 1.0, 100000.0, 1e6, 123456789.0, 5e-324, 2.2250738585072014e-308,
                                1.7976931348623157e308, 0.1, 1e-5, 9.999999e-5, 0.5};
  for (int i = 0; i < 20000; ++i) values.push_back(mantissa(rng) * std::pow(10.0, exponent(rng)));
  for (int i = 0; i < 2000; ++i) values.push_back(std::round(mantissa(rng) * 1e4));
  for (double x : values)
    if (std::isfinite(x)) {
      EXPECT_EQ(json_number(x), reference(x)) << x;
    }
}

TEST(FrameLog, LineParsesWithEveryFieldInOrder) {
  FrameReport r;
  r.frame = 7;
  r.time = 0.28;
  r.steps = 4;
  r.nodes = 121;
  r.faces = 200;
  r.saved = true;
  r.wall = {0.5, 0.25, 0.125, 0.0625, 0.03125, 0.015625, 1.0};
  const std::string line = frame_log_line(r);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(line.rfind("{\"frame\":7,\"time\":0.28,\"steps\":4,\"nodes\":121,\"faces\":200,\"saved\":true,\"wall\":{", 0),
            0u)
      << line;
  const Json::Value v = parse(line);
  EXPECT_EQ(v["wall"]["physics"].asDouble(), 0.5);
  EXPECT_EQ(v["wall"]["collision"].asDouble(), 0.25);
  EXPECT_EQ(v["wall"]["remeshing"].asDouble(), 0.125);
  EXPECT_EQ(v["wall"]["plasticity"].asDouble(), 0.0625);
  EXPECT_EQ(v["wall"]["fracture"].asDouble(), 0.03125);
  EXPECT_EQ(v["wall"]["output"].asDouble(), 0.015625);
  EXPECT_EQ(v["wall"]["total"].asDouble(), 1.0);
  EXPECT_EQ(v.size(), 7u);
}

TEST(FrameLog, ImpactZoneStatisticsWhenCollisionsRan) {
  FrameReport r;
  r.has_impact_zones = true;
  r.impact_zones.steps = 8;
  r.impact_zones.impacts = 41;
  r.impact_zones.zones = 5;
  r.impact_zones.iterations = 19;
  r.impact_zones.largest_zone = 12;
  r.impact_zones.fallback_zones = 1;
  r.impact_zones.unresolved_steps = 0;
  const Json::Value z = parse(frame_log_line(r))["impact_zones"];
  ASSERT_TRUE(z.isObject());
  EXPECT_EQ(z["steps"].asInt(), 8);
  EXPECT_EQ(z["impacts"].asInt(), 41);
  EXPECT_EQ(z["zones"].asInt(), 5);
  EXPECT_EQ(z["iterations"].asInt(), 19);
  EXPECT_EQ(z["largest_zone"].asInt(), 12);
  EXPECT_EQ(z["fallback_zones"].asInt(), 1);
  EXPECT_EQ(z["unresolved_steps"].asInt(), 0);
  r.has_impact_zones = false;
  EXPECT_FALSE(parse(frame_log_line(r)).isMember("impact_zones"));
}

TEST(FrameLog, TimeStepStatisticsWhenAdaptive) {
  FrameReport r;
  EXPECT_FALSE(parse(frame_log_line(r)).isMember("time_step"));
  r.has_time_step = true;
  r.substeps = 36;
  r.retries = 2;
  r.substep_level = 3;
  r.smallest_step = 1.25e-3;
  r.retry_cause = "cloth 0 \"node\" 7\\ moved\tfar";
  const Json::Value t = parse(frame_log_line(r))["time_step"];
  ASSERT_TRUE(t.isObject());
  EXPECT_EQ(t["substeps"].asInt(), 36);
  EXPECT_EQ(t["retries"].asInt(), 2);
  EXPECT_EQ(t["level"].asInt(), 3);
  EXPECT_EQ(t["smallest"].asDouble(), 1.25e-3);
  EXPECT_EQ(t["cause"].asString(), r.retry_cause);  // quotes, backslashes and control characters escaped
  EXPECT_FALSE(t.isMember("held"));  // only when a step held a persistent fallback
  r.held_steps = 4;
  EXPECT_EQ(parse(frame_log_line(r))["time_step"]["held"].asInt(), 4);
  r.retry_cause.clear();
  EXPECT_FALSE(parse(frame_log_line(r))["time_step"].isMember("cause"));
}

TEST(FrameLog, MeshSizesPerCloth) {
  FrameReport r;
  r.meshes.push_back({200, 0.01, 0.02, 0.05});
  r.meshes.push_back({8, 0.5, 0.75, 1.0});
  const Json::Value m = parse(frame_log_line(r))["meshes"];
  ASSERT_TRUE(m.isObject());
  EXPECT_EQ(m["cloth0"]["faces"].asInt(), 200);
  EXPECT_EQ(m["cloth0"]["edge_min"].asDouble(), 0.01);
  EXPECT_EQ(m["cloth0"]["edge_median"].asDouble(), 0.02);
  EXPECT_EQ(m["cloth0"]["edge_max"].asDouble(), 0.05);
  EXPECT_EQ(m["cloth1"]["faces"].asInt(), 8);
  EXPECT_EQ(m["cloth1"]["edge_max"].asDouble(), 1.0);
}

TEST(FrameLog, ProgressLineHasNullTotalWhenUnbounded) {
  FrameReport r;
  r.frame = 3;
  r.time = 0.12;
  r.faces = 8;
  r.nodes = 9;
  r.wall.total = 0.01;
  EXPECT_EQ(progress_json_line(r, 10), "{\"frame\":3,\"total\":10,\"time\":0.12,\"faces\":8,\"nodes\":9,\"wall\":0.01}");
  EXPECT_TRUE(parse(progress_json_line(r, INFINITY))["total"].isNull());
}

TEST(OutputFiles, NamesFollowArcsimNumbering) {
  EXPECT_EQ(cloth_frame_file_name(0, 0), "00000_00.obj");
  EXPECT_EQ(cloth_frame_file_name(123, 4), "00123_04.obj");
  EXPECT_EQ(cloth_frame_file_name(123456, 12), "123456_12.obj");
  EXPECT_EQ(obstacle_frame_file_name(5, 1), "00005_obs01.obj");
  EXPECT_EQ(static_obstacle_file_name(2), "obs02.obj");
  for (const char* ours : {"conf.json", "log.jsonl", "00001_00.obj", "obs00.obj", "00001_obs03.obj"})
    EXPECT_TRUE(is_output_file_name(ours)) << ours;
  for (const char* theirs : {"square.obj", "meshes", "conf.json5", "paper.json", "obs", "log.json"})
    EXPECT_FALSE(is_output_file_name(theirs)) << theirs;
}

TEST(Progress, DurationsForPeople) {
  EXPECT_EQ(format_duration(0), "0.0 s");
  EXPECT_EQ(format_duration(12.34), "12.3 s");
  EXPECT_EQ(format_duration(245), "4m05s");
  EXPECT_EQ(format_duration(2 * 3600 + 3 * 60 + 10), "2h03m");
  EXPECT_EQ(format_duration(NAN), "?");
}

TEST(Progress, JsonStyleWinsOverQuietAndTerminalDecidesTheRest) {
  EXPECT_EQ(choose_progress_style(true, true, true), ProgressStyle::kJson);
  EXPECT_EQ(choose_progress_style(true, false, true), ProgressStyle::kQuiet);
  EXPECT_EQ(choose_progress_style(false, false, true), ProgressStyle::kLive);
  EXPECT_EQ(choose_progress_style(false, false, false), ProgressStyle::kLines);
}

TEST(Progress, LiveLineIsRewrittenInPlaceAndEndedOnce) {
  std::ostringstream out, err;
  const Console console{out, err, true};
  Progress progress(ProgressStyle::kLive, console, 4);
  FrameReport r;
  r.faces = 200;
  r.wall.total = 0.5;
  for (int f = 1; f <= 2; ++f) {
    r.frame = f;
    r.time = 0.04 * f;
    progress.frame_done(r);
  }
  progress.end_line();
  progress.end_line();  // the second call must not add another newline
  const std::string text = err.str();
  EXPECT_EQ(out.str(), "");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\r'), 2);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  EXPECT_NE(text.find("frame 2/4"), std::string::npos) << text;
  EXPECT_NE(text.find("ETA 1.0 s"), std::string::npos) << text;  // 0.5 s per frame, 2 frames to go
}

TEST(Progress, LinesStyleReportsAboutEveryFivePercent) {
  std::ostringstream out, err;
  const Console console{out, err, false};
  Progress progress(ProgressStyle::kLines, console, 100);
  FrameReport r;
  for (int f = 1; f <= 100; ++f) {
    r.frame = f;
    progress.frame_done(r);
  }
  const std::string text = err.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 21);  // frame 1, then each 5% up to 100%
  EXPECT_EQ(text.find('\r'), std::string::npos);
}

}  // namespace
}  // namespace arcsim
