// The rviz panel plugin as rviz finds it: package.xml's <rviz plugin=...> export names
// rviz_plugins.xml, which declares camera_imu_alignment/AlignmentPanel in a library that exists and
// registers that class (PLUGINLIB_EXPORT_CLASS); the panel keeps its namespace and frame-label
// switch through rviz's config (save, load); config/alignment.rviz loads it. Fails when any link of
// that chain is broken. Needs the workspace's environment (ROS_PACKAGE_PATH: the catkin test
// runner, or devel/setup.bash), no display (Qt's offscreen platform) and no ROS master (the panel
// subscribes only in onInitialize, which rviz calls and this test does not).
#include <gtest/gtest.h>
#include <rviz/config.h>
#include <rviz/panel.h>
#include <pluginlib/class_loader.hpp>

#include <yaml-cpp/yaml.h>

#include <QApplication>
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

const char* const kPanelClass = "camera_imu_alignment/AlignmentPanel";

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

TEST(RvizPlugin, ThePanelIsExportedAndItsLibraryCreatesIt) {
  pluginlib::ClassLoader<rviz::Panel> loader("rviz", "rviz::Panel");
  const std::vector<std::string> declared = loader.getDeclaredClasses();
  ASSERT_TRUE(loader.isClassAvailable(kPanelClass))
      << kPanelClass << " is not declared by any package's <rviz plugin=...> export; declared: "
      << joined(declared);
  EXPECT_EQ(loader.getClassType(kPanelClass), "camera_imu_alignment::AlignmentPanel");
  std::shared_ptr<rviz::Panel> panel;
  try {
    panel = loader.createSharedInstance(kPanelClass);
  } catch (const pluginlib::PluginlibException& e) {
    FAIL() << "the library declared for " << kPanelClass << " ("
           << loader.getClassLibraryPath(kPanelClass) << ") does not create it: " << e.what();
  }
  ASSERT_TRUE(panel);
  EXPECT_TRUE(panel->inherits("camera_imu_alignment::AlignmentPanel"));
  panel.reset();  // before the loader unloads the library
}

TEST(RvizPlugin, TheDefaultConfigLoadsThePanel) {
  const YAML::Node config = YAML::LoadFile(ALIGNMENT_RVIZ);
  pluginlib::ClassLoader<rviz::Panel> loader("rviz", "rviz::Panel");
  int ours = 0;
  for (const YAML::Node& panel : config["Panels"]) {
    const std::string class_name = panel["Class"].as<std::string>();
    if (class_name.rfind("camera_imu_alignment/", 0) != 0) continue;
    ++ours;
    EXPECT_TRUE(loader.isClassAvailable(class_name)) << ALIGNMENT_RVIZ << " names " << class_name;
    EXPECT_EQ(panel["Namespace"].as<std::string>(), "/camera_imu_alignment");
  }
  EXPECT_EQ(ours, 1) << ALIGNMENT_RVIZ << " should load the alignment panel once";
}

TEST(RvizPlugin, ThePanelKeepsItsSettingsInTheRvizConfig) {
  pluginlib::ClassLoader<rviz::Panel> loader("rviz", "rviz::Panel");
  std::shared_ptr<rviz::Panel> panel = loader.createSharedInstance(kPanelClass);
  rviz::Config defaults;
  panel->save(defaults);
  QString name_space;
  ASSERT_TRUE(defaults.mapGetString("Namespace", &name_space));
  EXPECT_EQ(name_space.toStdString(), "/camera_imu_alignment");
  bool labels = false;
  ASSERT_TRUE(defaults.mapGetBool("Frame labels", &labels));
  EXPECT_TRUE(labels);

  // A config as rviz reads it from a file: the namespace as typed (normalised), labels off.
  rviz::Config loaded;
  loaded.mapSetValue("Namespace", "robot/cia/");
  loaded.mapSetValue("Frame labels", false);
  panel->load(loaded);
  rviz::Config saved;
  panel->save(saved);
  ASSERT_TRUE(saved.mapGetString("Namespace", &name_space));
  EXPECT_EQ(name_space.toStdString(), "/robot/cia");
  ASSERT_TRUE(saved.mapGetBool("Frame labels", &labels));
  EXPECT_FALSE(labels);

  // A namespace that is not a ROS name is refused: the panel keeps listening where it did.
  rviz::Config bad;
  bad.mapSetValue("Namespace", "robot cia");
  panel->load(bad);
  rviz::Config after_bad;
  panel->save(after_bad);
  ASSERT_TRUE(after_bad.mapGetString("Namespace", &name_space));
  EXPECT_EQ(name_space.toStdString(), "/robot/cia");
  panel.reset();
}

}  // namespace

int main(int argc, char** argv) {
  setenv("QT_QPA_PLATFORM", "offscreen", 1);  // widgets without a display
  QApplication application(argc, argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
