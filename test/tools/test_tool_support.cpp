// Tests of the tools' shared pieces: pose algebra, time stamp repair, the CARMEN log plan.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "tool_support.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

TEST(PoseAlgebra, ComposeWithInverseIsIdentity) {
  const wavog::Pose2 a{1.5, -2.0, 2.9};
  const wavog::Pose2 b{-0.3, 0.7, -3.0};
  const wavog::Pose2 ab = wavog_tools::compose(a, b);
  const wavog::Pose2 back = wavog_tools::compose(wavog_tools::inverse(a), ab);
  EXPECT_NEAR(back.x, b.x, 1e-12);
  EXPECT_NEAR(back.y, b.y, 1e-12);
  EXPECT_NEAR(back.theta, b.theta, 1e-12);
  EXPECT_NEAR(ab.theta, wavog_tools::wrapAngle(2.9 - 3.0), 1e-12);
  const wavog::Pose2 rot = wavog_tools::compose({0, 0, M_PI / 2}, {1, 0, 0});
  EXPECT_NEAR(rot.x, 0.0, 1e-12);
  EXPECT_NEAR(rot.y, 1.0, 1e-12);
  EXPECT_NEAR(wavog_tools::wrapAngle(-M_PI), M_PI, 1e-12);
}

TEST(StampRepair, ShiftsRelativeStampsAndKeepsAbsoluteOnes) {
  wavog_tools::StampRepair rel(10.0, 1.6e9);
  EXPECT_DOUBLE_EQ(rel.repair(0.25), 1.6e9 + 0.25);
  EXPECT_DOUBLE_EQ(rel.repair(0.5), 1.6e9 + 0.5);
  EXPECT_EQ(rel.shifted(), 2u);
  wavog_tools::StampRepair abs(10.0, 1.6e9);
  EXPECT_DOUBLE_EQ(abs.repair(1134864642.914187), 1134864642.914187);
  EXPECT_EQ(abs.shifted(), 0u);
  EXPECT_TRUE(abs.report().empty());
}

TEST(StampRepair, ClampsBackwardStepsAndSynthesisesMissingStamps) {
  wavog_tools::StampRepair r(20.0, 1000.0);
  const double a = r.repair(2e9);
  const double b = r.repair(2e9);         // equal: clamped
  const double c = r.repair(2e9 - 0.05);  // backward: clamped
  const double d = r.repair(0.0);         // missing: + 1 / rate
  const double e = r.repair(std::nan(""));
  EXPECT_GT(b, a);
  EXPECT_GT(c, b);
  EXPECT_NEAR(d, c + 0.05, 1e-6);
  EXPECT_NEAR(e, d + 0.05, 1e-6);
  EXPECT_EQ(r.clamped(), 2u);
  EXPECT_EQ(r.synthesised(), 2u);
  EXPECT_NEAR(r.largestBackwardStep(), 0.05, 1e-6);
  EXPECT_EQ(r.report().size(), 2u);
  wavog_tools::StampRepair zeros(10.0, 1.6e9);
  EXPECT_DOUBLE_EQ(zeros.repair(0.0), 1.6e9);
  EXPECT_NEAR(zeros.repair(0.0), 1.6e9 + 0.1, 1e-6);
}

TEST(StampRepair, KeepsTheLoggedMicroseconds) {
  wavog_tools::StampRepair r(10.0, 1.6e9);
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  wavog_tools::toSecNsec(r.repair(1134864642.914187), &sec, &nsec);
  EXPECT_EQ(sec, 1134864642u);
  EXPECT_EQ(nsec, 914187000u);
  wavog_tools::toSecNsec(1.9999999, &sec, &nsec);
  EXPECT_EQ(sec, 2u);
  EXPECT_EQ(nsec, 0u);
}

TEST(CarmenLogPlan, FrontRearAndDuplicateRobotLaser) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("wavog_plan_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "plan.log").string();
  {
    std::ofstream out(path);
    std::string r180;
    for (int i = 0; i < 180; ++i) r180 += "1.0 ";
    out << "FLASER 180 " << r180 << "1 2 0.5 1 2 0.5 1.0 h 1.0\n";
    out << "RLASER 180 " << r180 << "0.8 2 3.64159 1 2 0.5 1.1 h 1.1\n";
    out << "ROBOTLASER1 0 -1.57 3.14 0.5 80 0.01 0 2 1 1 0 1 2 0.5 1 2 0.5 0 0 0 0 0 1.2 h 1.2\n";
    out << "FLASER 180 " << r180 << "1 2 0.5 1 2 0.5 1.3 h 1.3\n";
  }
  const wavog_tools::CarmenLogPlan plan = wavog_tools::planCarmenLog(path);
  ASSERT_EQ(plan.lasers.size(), 3u);
  EXPECT_EQ(plan.scans_used, 3u);
  EXPECT_EQ(plan.skipped_duplicates, 1u);
  ASSERT_NE(plan.laserFor("FLASER"), nullptr);
  EXPECT_EQ(plan.laserFor("FLASER")->topic, "/front_laser/scan");
  EXPECT_EQ(plan.laserFor("FLASER")->scans, 2u);
  EXPECT_EQ(plan.laserFor("ROBOTLASER1"), nullptr);
  const wavog_tools::CarmenLaser* rear = plan.laserFor("RLASER");
  ASSERT_NE(rear, nullptr);
  EXPECT_EQ(rear->frame, "rear_laser");
  EXPECT_TRUE(rear->mount_from_log);
  // rear laser 0.2 m behind base_link (robot heading 0.5 rad), turned by pi.
  EXPECT_NEAR(rear->mount.x, -0.2 * std::cos(0.5), 1e-9);
  EXPECT_NEAR(std::fabs(rear->mount.theta), 3.14159, 1e-5);
  std::filesystem::remove_all(dir);
}

TEST(TextHelpers, Lists) {
  EXPECT_EQ(wavog_tools::splitList(" a, b,,c "), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(wavog_tools::stripSlash("/laser"), "laser");
  EXPECT_EQ(wavog_tools::stripSlash("laser"), "laser");
}

TEST(TextHelpers, WrapText) {
  EXPECT_EQ(wavog_tools::wrapText("aa bb  cc dddddd e", 5), "aa bb\ncc\ndddddd\ne");
  EXPECT_EQ(wavog_tools::wrapText("", 5), "");
}

TEST(TextHelpers, StrictNumbers) {
  EXPECT_DOUBLE_EQ(wavog_tools::parseNumber("--rate", "0.25"), 0.25);
  EXPECT_DOUBLE_EQ(wavog_tools::parseNumber("--epoch", "-3e2"), -300.0);
  for (const char* bad : {"0.5x", "abc", "", "inf", "nan", "1e999", "2 "}) {
    try {
      wavog_tools::parseNumber("--rate", bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), std::string("--rate: not a number: '") + bad + "'");
    }
  }
  EXPECT_EQ(wavog_tools::parseInteger("--scale", "7", 0), 7);
  EXPECT_EQ(wavog_tools::parseInteger("--scale", "0", 0), 0);
  for (const char* bad : {"2.5", "-1", "3x", "", "99999999999999999999"}) {
    try {
      wavog_tools::parseInteger("--scale", bad, 0);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()),
                std::string("--scale: not a whole number >= 0: '") + bad + "'");
    }
  }
}

TEST(CommandLine, NumbersAreReadWholeAndUsageErrorsGiveStatusTwo) {
  auto runWith = [](std::vector<std::string> args, double* rate, long* reps, bool* ran) {
    CLI::App app{"test tool", "wavog_test"};
    wavog_tools::addNumber(&app, "-r,--rate", rate, "a rate");
    wavog_tools::addInteger(&app, "--reps", reps, 1, "repetitions");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    *ran = false;
    return wavog_tools::runTool(&app, static_cast<int>(argv.size()), argv.data(), [ran] {
      *ran = true;
      return 0;
    });
  };
  double rate = 1.0;
  long reps = 3;
  bool ran = false;
  EXPECT_EQ(runWith({"wavog_test", "--rate", "0.25", "--reps", "4"}, &rate, &reps, &ran), 0);
  EXPECT_TRUE(ran);
  EXPECT_DOUBLE_EQ(rate, 0.25);
  EXPECT_EQ(reps, 4);
  EXPECT_EQ(runWith({"wavog_test", "-r", "-2e1"}, &rate, &reps, &ran), 0);
  EXPECT_DOUBLE_EQ(rate, -20.0);
  testing::internal::CaptureStderr();
  EXPECT_EQ(runWith({"wavog_test", "--rate", "0.05x"}, &rate, &reps, &ran), 1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find(
                "wavog_test: error: --rate: not a number: '0.05x'"),
            std::string::npos);
  testing::internal::CaptureStderr();
  EXPECT_EQ(runWith({"wavog_test", "--reps", "0"}, &rate, &reps, &ran), 1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--reps: not a whole number >= 1: '0'"),
            std::string::npos);
  EXPECT_FALSE(ran);
  testing::internal::CaptureStderr();
  EXPECT_EQ(runWith({"wavog_test", "--no-such-option"}, &rate, &reps, &ran), 2);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("Usage: wavog_test"), std::string::npos) << err;
  EXPECT_NE(err.find("--rate NUM"), std::string::npos) << err;
  testing::internal::CaptureStdout();
  EXPECT_EQ(runWith({"wavog_test", "--help"}, &rate, &reps, &ran), 0);
  EXPECT_NE(testing::internal::GetCapturedStdout().find("repetitions"), std::string::npos);
  EXPECT_FALSE(ran);
}

TEST(Json, WrittenIndentedInKeyOrder) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("wavog_json_" + std::to_string(::getpid())))
          .string();
  nlohmann::ordered_json j;
  j["b"] = 1;
  j["a"] = std::nan("");
  j["list"] = {"x\"y"};
  wavog_tools::writeJson(path, j);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "{\n  \"b\": 1,\n  \"a\": null,\n  \"list\": [\n    \"x\\\"y\"\n  ]\n}\n");
  std::filesystem::remove(path);
  EXPECT_THROW(wavog_tools::writeJson("/no/such/dir/x.json", j), std::runtime_error);
}

}  // namespace
