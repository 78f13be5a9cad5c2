// Seed maps (include/sowing_robot/seed_map/): the CSV read back equals the seeds bit for bit; the GeoJSON is
// RFC 7946 (a FeatureCollection of [lon, lat] Points) at the coordinates GeographicLib gives for a known origin,
// with x east and y north; a path that cannot be written leaves nothing behind; GeoJSON without an origin is
// refused; a bag's seed record reads back, and a corrupt bag or one without seeds is one line; the seed_map
// command end to end (exit codes, one line on stderr).
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <std_msgs/String.h>
#include <sys/wait.h>
#include <unistd.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sowing_robot/ros/common/seed_message.h"
#include "sowing_robot/seed_map/bag_seeds.h"
#include "sowing_robot/seed_map/seed_map.h"

namespace fs = std::filesystem;
using sowing_robot::core::Seed;
namespace sm = sowing_robot::seed_map;

namespace {

const sm::GeoOrigin kOrigin{48.2082, 16.3738, 180.0};  // a field near Vienna

Seed seed(double t, double x, double y, double bx, double by, int row, double depth, bool detour) {
  Seed s;
  s.t = t;
  s.truth = {x, y};
  s.believed = {bx, by};
  s.row = row;
  s.depth = depth;
  s.detour = detour;
  return s;
}

std::vector<Seed> someSeeds() {
  return {seed(2.002, 0.1, 3.0, 0.1003, 2.998, 0, 0.04, false),
          seed(10.5, 100.0, 0.0, 99.9, 0.05, 1, 0.035, false),  // 100 m east
          seed(17.25, 0.0, 50.0, 0.0, 50.0, 2, 0.045, true),    // 50 m north
          seed(20.0 / 3.0, -12.345678901234567, -1e-9, -12.3, 0.0, -1, 1.0 / 3.0, false)};
}

std::string readFile(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

class SeedMap : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sowing_seed_map_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  fs::path dir_;
};

TEST_F(SeedMap, CsvReadsBackBitForBit) {
  const std::vector<Seed> seeds = someSeeds();
  const std::string path = (dir_ / "seeds.csv").string();
  ASSERT_EQ(sm::writeCsv(path, seeds), "");
  const std::string text = readFile(path);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,x,y,believed_x,believed_y,row,depth,detour");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + static_cast<long>(seeds.size()));
  std::vector<Seed> back;
  ASSERT_EQ(sm::readCsv(path, back), "");
  ASSERT_EQ(back.size(), seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(back[i].t, seeds[i].t);
    EXPECT_EQ(back[i].truth, seeds[i].truth);
    EXPECT_EQ(back[i].believed, seeds[i].believed);
    EXPECT_EQ(back[i].row, seeds[i].row);
    EXPECT_EQ(back[i].depth, seeds[i].depth);
    EXPECT_EQ(back[i].detour, seeds[i].detour);
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"seeds.csv"});  // no temporary file left
}

TEST_F(SeedMap, GeoJsonIsWgs84AtTheOrigin) {
  const std::vector<Seed> seeds = someSeeds();
  const std::string path = (dir_ / "seeds.geojson").string();
  ASSERT_EQ(sm::writeGeoJson(path, seeds, kOrigin), "");
  const nlohmann::json doc = nlohmann::json::parse(readFile(path));
  EXPECT_EQ(doc["type"], "FeatureCollection");
  ASSERT_EQ(doc["features"].size(), seeds.size());
  const GeographicLib::LocalCartesian local(kOrigin.latitude, kOrigin.longitude, kOrigin.altitude);
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    SCOPED_TRACE(i);
    const nlohmann::json& f = doc["features"][i];
    EXPECT_EQ(f["type"], "Feature");
    EXPECT_EQ(f["geometry"]["type"], "Point");
    double lat, lon, h;
    local.Reverse(seeds[i].truth.x(), seeds[i].truth.y(), 0.0, lat, lon, h);
    ASSERT_EQ(f["geometry"]["coordinates"].size(), 2u);
    EXPECT_EQ(f["geometry"]["coordinates"][0].get<double>(), lon);  // RFC 7946: longitude first
    EXPECT_EQ(f["geometry"]["coordinates"][1].get<double>(), lat);
    const nlohmann::json& p = f["properties"];
    EXPECT_EQ(p["t"].get<double>(), seeds[i].t);
    EXPECT_EQ(p["row"].get<int>(), seeds[i].row);
    EXPECT_EQ(p["depth"].get<double>(), seeds[i].depth);
    EXPECT_EQ(p["detour"].get<bool>(), seeds[i].detour);
    EXPECT_EQ(p["x"].get<double>(), seeds[i].truth.x());
    EXPECT_EQ(p["believed_y"].get<double>(), seeds[i].believed.y());
    local.Reverse(seeds[i].believed.x(), seeds[i].believed.y(), 0.0, lat, lon, h);
    EXPECT_EQ(p["believed_lon"].get<double>(), lon);
    EXPECT_EQ(p["believed_lat"].get<double>(), lat);
    EXPECT_NEAR(p["believed_offset"].get<double>(), (seeds[i].believed - seeds[i].truth).norm(), 1e-15);
  }
  // Independently of LocalCartesian: x is east and y north, at the right distance. The plane lies at the origin's
  // altitude, the geodesic on the ellipsoid: shorter by altitude / radius (2.8e-5 here).
  const auto geodesic = [&](std::size_t i, double& distance, double& azimuth) {
    const nlohmann::json& c = doc["features"][i]["geometry"]["coordinates"];
    double azi2;
    GeographicLib::Geodesic::WGS84().Inverse(kOrigin.latitude, kOrigin.longitude, c[1].get<double>(),
                                             c[0].get<double>(), distance, azimuth, azi2);
  };
  const double scale = 1.0 - kOrigin.altitude / 6.371e6;
  double s, azi;
  geodesic(1, s, azi);
  EXPECT_NEAR(s, 100.0 * scale, 2e-4);
  EXPECT_NEAR(azi, 90.0, 0.01);
  geodesic(2, s, azi);
  EXPECT_NEAR(s, 50.0 * scale, 1e-4);
  EXPECT_NEAR(azi, 0.0, 0.01);
}

TEST_F(SeedMap, NonFiniteNumbersAreJsonNull) {
  std::vector<Seed> seeds = someSeeds();
  seeds[0].believed.x() = std::numeric_limits<double>::quiet_NaN();
  const nlohmann::json doc = nlohmann::json::parse(sm::geoJsonText(seeds, kOrigin));
  EXPECT_TRUE(doc["features"][0]["properties"]["believed_x"].is_null());
  EXPECT_TRUE(doc["features"][0]["geometry"]["coordinates"][0].is_number());
}

TEST_F(SeedMap, PathThatCannotBeWrittenIsOneLineAndLeavesNothing) {
  const std::string missing = (dir_ / "no_such_dir" / "seeds.csv").string();
  const std::string error = sm::writeCsv(missing, someSeeds());
  EXPECT_EQ(error.rfind("cannot write " + missing + ": ", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  // The target is a directory: the map is written in full beside it, then the rename fails and it goes.
  fs::create_directories(dir_ / "taken" / "inside");
  const std::string taken = (dir_ / "taken").string();
  EXPECT_NE(sm::writeGeoJson(taken, someSeeds(), kOrigin), "");
  EXPECT_EQ(entries(), std::vector<std::string>{"taken"});
  // An existing map is replaced whole or kept as it was.
  const std::string path = (dir_ / "seeds.csv").string();
  ASSERT_EQ(sm::writeCsv(path, someSeeds()), "");
  const std::string before = readFile(path);
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
  const bool can_still_write = ::access(dir_.c_str(), W_OK) == 0;  // root ignores the mode
  const std::string refused = sm::writeCsv(path, {});
  fs::permissions(dir_, fs::perms::owner_all);
  if (!can_still_write) {
    EXPECT_NE(refused, "");
    EXPECT_EQ(readFile(path), before);
  }
}

TEST_F(SeedMap, GeoJsonWithoutOriginIsRefused) {
  const std::string path = (dir_ / "seeds.geojson").string();
  const std::string error = sm::writeGeoJson(path, someSeeds(), std::nullopt);
  EXPECT_NE(error.find("--origin LAT,LON[,ALT]"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(path));
  sm::Options o;
  EXPECT_NE(sm::parseArguments({"run.bag", "--geojson", path}, o).find("--origin"), std::string::npos);
  EXPECT_EQ(sm::parseArguments({"run.bag", "--geojson", path, "--origin", "48.2,16.37"}, o), "");
  ASSERT_TRUE(o.origin.has_value());
  EXPECT_EQ(o.origin->altitude, 0.0);
  EXPECT_EQ(sm::parseArguments({"run.bag", "--csv", "a.csv"}, o), "");  // CSV needs no origin
}

TEST(SeedMapArguments, OriginAndUsage) {
  sm::GeoOrigin g;
  EXPECT_EQ(sm::parseOrigin("48.2082,16.3738,180", g), "");
  EXPECT_EQ(g.latitude, 48.2082);
  EXPECT_EQ(g.longitude, 16.3738);
  EXPECT_EQ(g.altitude, 180.0);
  for (const char* bad : {"", "48.2", "48.2,", "48.2,16.3,1,2", "x,16", "91,0", "0,181", "0,nan", "48.2;16.3"})
    EXPECT_NE(sm::parseOrigin(bad, g), "") << bad;
  sm::Options o;
  EXPECT_NE(sm::parseArguments({}, o), "");
  EXPECT_NE(sm::parseArguments({"run.bag"}, o), "");  // nothing to write
  EXPECT_NE(sm::parseArguments({"a.bag", "b.bag", "--csv", "x"}, o), "");
  EXPECT_NE(sm::parseArguments({"a.bag", "--csv"}, o), "");
  EXPECT_EQ(sm::parseArguments({"a.bag", "--bogus"}, o), "unknown option '--bogus' (see seed_map --help)");
}

// --- bags --------------------------------------------------------------------------------------------------

void writeBag(const std::string& path, const std::vector<std::pair<std::string, Seed>>& seeds,
              bool other_topic = true) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  if (other_topic) {
    std_msgs::String s;
    s.data = "not a seed";
    bag.write("/chatter", ros::Time(1.0), s);
  }
  for (const auto& [topic, seed] : seeds)
    bag.write(topic, ros::Time(seed.t), sowing_robot::seedMessage(seed, ros::Time(seed.t), "odom"));
}

TEST_F(SeedMap, BagSeedsReadBack) {
  const std::string path = (dir_ / "run.bag").string();
  std::vector<std::pair<std::string, Seed>> recorded;
  for (const Seed& s : someSeeds()) recorded.emplace_back("/seeds/record", s);
  writeBag(path, recorded);
  // A bag reads back in time order (its messages are recorded at the seeds' stamps here).
  std::sort(recorded.begin(), recorded.end(), [](const auto& a, const auto& b) { return a.second.t < b.second.t; });
  std::vector<Seed> back;
  std::string topic;
  ASSERT_EQ(sm::readBagSeeds(path, "", back, topic), "");
  EXPECT_EQ(topic, "/seeds/record");
  ASSERT_EQ(back.size(), recorded.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_NEAR(back[i].t, recorded[i].second.t, 1e-9);  // the stamp holds nanoseconds
    EXPECT_EQ(back[i].truth, recorded[i].second.truth);
    EXPECT_EQ(back[i].believed, recorded[i].second.believed);
    EXPECT_EQ(back[i].row, recorded[i].second.row);
    EXPECT_EQ(back[i].depth, recorded[i].second.depth);
    EXPECT_EQ(back[i].detour, recorded[i].second.detour);
  }
  EXPECT_EQ(sm::readBagSeeds(path, "seeds/record", back, topic), "");  // relative names as the launch gives them
  EXPECT_NE(sm::readBagSeeds(path, "/chatter", back, topic).find("not of type"), std::string::npos);
  EXPECT_NE(sm::readBagSeeds(path, "/nothing", back, topic).find("no topic /nothing"), std::string::npos);
}

TEST_F(SeedMap, SeedsOnSeveralTopicsNeedATopic) {
  const std::string path = (dir_ / "fleet.bag").string();
  writeBag(path, {{"/robot_0/seeds/record", someSeeds()[0]}, {"/robot_1/seeds/record", someSeeds()[1]}});
  std::vector<Seed> back;
  std::string topic;
  EXPECT_NE(sm::readBagSeeds(path, "", back, topic).find("--topic"), std::string::npos);
  ASSERT_EQ(sm::readBagSeeds(path, "robot_1/seeds/record", back, topic), "");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].truth, someSeeds()[1].truth);
}

TEST_F(SeedMap, CorruptOrSeedlessBagIsOneLine) {
  std::vector<Seed> back;
  std::string topic;
  const std::string seedless = (dir_ / "seedless.bag").string();
  writeBag(seedless, {});
  std::string error = sm::readBagSeeds(seedless, "", back, topic);
  EXPECT_EQ(error.rfind("no seeds in " + seedless, 0), 0u) << error;
  const std::string garbage = (dir_ / "garbage.bag").string();
  std::ofstream(garbage) << "this is not a bag\n";
  error = sm::readBagSeeds(garbage, "", back, topic);
  EXPECT_EQ(error.rfind("cannot read bag " + garbage, 0), 0u) << error;
  // A bag cut short (a crashed recorder): its index is gone.
  const std::string good = (dir_ / "good.bag").string(), cut = (dir_ / "cut.bag").string();
  writeBag(good, {{"/seeds/record", someSeeds()[0]}, {"/seeds/record", someSeeds()[1]}});
  const std::string bytes = readFile(good);
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  error = sm::readBagSeeds(cut, "", back, topic);
  EXPECT_NE(error, "");
  EXPECT_EQ(sm::readBagSeeds((dir_ / "absent.bag").string(), "", back, topic).rfind("cannot read bag", 0), 0u);
  for (const std::string& e : {error, sm::readBagSeeds(garbage, "", back, topic)})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

// --- the command ---------------------------------------------------------------------------------------------

struct Outcome {
  int status = -1;
  std::string out, err;
};

Outcome runSeedMap(const fs::path& dir, const std::string& args) {
  const std::string line = std::string(SOWING_SEED_MAP_BIN) + " " + args + " > " + (dir / "stdout").string() + " 2> " +
                           (dir / "stderr").string() + " < /dev/null";
  const int raw = std::system(line.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = readFile(dir / "stdout");
  o.err = readFile(dir / "stderr");
  fs::remove(dir / "stdout");
  fs::remove(dir / "stderr");
  return o;
}

void expectOneLine(const Outcome& o, int status, const std::string& part) {
  EXPECT_EQ(o.status, status) << o.err;
  EXPECT_EQ(o.err.rfind("seed_map: ", 0), 0u) << o.err;
  EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "not one line:\n" << o.err;
  EXPECT_NE(o.err.find(part), std::string::npos) << o.err;
}

TEST_F(SeedMap, Command) {
  const std::string bag = (dir_ / "run.bag").string();
  std::vector<std::pair<std::string, Seed>> recorded;
  for (const Seed& s : someSeeds()) recorded.emplace_back("/seeds/record", s);
  writeBag(bag, recorded);
  const fs::path csv = dir_ / "seeds.csv", geojson = dir_ / "seeds.geojson";
  Outcome o = runSeedMap(
      dir_, bag + " --csv " + csv.string() + " --geojson " + geojson.string() + " --origin 48.2082,16.3738,180");
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("4 seeds from /seeds/record"), std::string::npos) << o.out;
  std::vector<Seed> back;
  EXPECT_EQ(sm::readCsv(csv.string(), back), "");
  EXPECT_EQ(back.size(), 4u);
  EXPECT_EQ(nlohmann::json::parse(readFile(geojson))["features"].size(), 4u);

  expectOneLine(runSeedMap(dir_, bag + " --geojson " + (dir_ / "x.geojson").string()), 2, "--origin");
  EXPECT_FALSE(fs::exists(dir_ / "x.geojson"));
  const std::string garbage = (dir_ / "garbage.bag").string();
  std::ofstream(garbage) << "this is not a bag\n";
  expectOneLine(runSeedMap(dir_, garbage + " --csv " + (dir_ / "y.csv").string()), 1, "cannot read bag");
  const std::string seedless = (dir_ / "seedless.bag").string();
  writeBag(seedless, {});
  expectOneLine(runSeedMap(dir_, seedless + " --csv " + (dir_ / "y.csv").string()), 1, "no seeds in");
  expectOneLine(runSeedMap(dir_, bag + " --csv " + (dir_ / "no_dir" / "y.csv").string()), 1, "cannot write");
  EXPECT_FALSE(fs::exists(dir_ / "y.csv"));
}

}  // namespace
