// The online calibrator with a camera_info whose focal lengths are not the camera's (rendered
// images, the simulator's truth): the snapshot's message (~status, diagnostics) and the verdict
// name camera_info, nothing is broadcast, and a mount change that really happened is not declared
// while the camera model is flagged (a wrong focal length bends every pose; the remount test
// cannot tell the two apart). The same recording with the true camera_info finds the remount:
// the test can fail.
#include <gtest/gtest.h>

#include <string>

#include "camera_imu_alignment/simulation/sim_config.h"
#include "pipeline_simulation.h"

namespace camera_imu_alignment {
namespace {

namespace sim = simulation;

/// Passes everything on to `inner`, camera_info's fx, fy times `focal_scale`.
class ScaledCameraInfo : public SampleSink {
 public:
  ScaledCameraInfo(SampleSink* inner, double focal_scale)
      : inner_(inner), focal_scale_(focal_scale) {}
  void addImu(const ImuSample& s) override { inner_->addImu(s); }
  void addMagnetic(const MagneticSample& s) override { inner_->addMagnetic(s); }
  bool setCameraIntrinsics(const CameraIntrinsics& intrinsics) override {
    CameraIntrinsics scaled = intrinsics;
    scaled.K(0, 0) *= focal_scale_;
    scaled.K(1, 1) *= focal_scale_;
    return inner_->setCameraIntrinsics(scaled);
  }
  void addFrame(const CameraFrame& f) override { inner_->addFrame(f); }
  void rejectInput(RejectReason r, InputStream s, const std::string& d) override {
    inner_->rejectInput(r, s, d);
  }
  ImuOrientationSource imuOrientationSource() const override {
    return inner_->imuOrientationSource();
  }

 private:
  SampleSink* inner_;
  double focal_scale_;
};

struct Outcome {
  CalibrationSnapshot snapshot;
  int broadcasts = 0;
};

/// The simulator's remount recording (the mount turns by 10 deg halfway), camera_info x scale.
Outcome runRemount(double focal_scale) {
  sim::SimulationConfig c;
  c.seed = 71;
  EXPECT_TRUE(sim::applyScenario("remount", &c));
  const sim::SimulationRun run(c);
  OnlineSettings online;
  online.threaded = false;
  Outcome out;
  OnlineCallbacks callbacks;
  callbacks.on_broadcast = [&out](const BroadcastEstimate&) { ++out.broadcasts; };
  PipelineSettings settings;
  settings.joint = test::jointSettingsFor(c);
  OnlineCalibrator calibrator(test::simulatedTarget(c), settings, online, callbacks);
  ScaledCameraInfo sink(&calibrator, focal_scale);
  test::feedRenderedRun(run, &sink);
  calibrator.finish();
  calibrator.waitForSolves();
  out.snapshot = calibrator.snapshot(SnapshotContents::kWithHistory);
  return out;
}

TEST(OnlineCameraModel, AWrongFocalLengthIsNamedAndNoRemountIsDeclared) {
  const Outcome wrong = runRemount(1.3);
  const CalibrationSnapshot& s = wrong.snapshot;
  EXPECT_TRUE(s.camera_model.wrong);
  EXPECT_NEAR(s.camera_model.focal_scale * 1.3, 1.0, 0.02);
  EXPECT_NE(s.message.find("the camera intrinsics in camera_info do not fit the images"),
            std::string::npos)
      << s.message;
  EXPECT_EQ(s.remounts, 0) << s.message;
  EXPECT_TRUE(s.remount_events.empty());
  EXPECT_EQ(wrong.broadcasts, 0);
  ASSERT_TRUE(s.verdict.has_value());
  EXPECT_FALSE(s.verdict->passed);
  EXPECT_EQ(s.verdict->text.rfind("FAILED: the camera intrinsics in camera_info", 0), 0u)
      << s.verdict->text;

  // The control: the true camera_info, the same recording: the check is silent and the remount
  // is found.
  const Outcome right = runRemount(1.0);
  EXPECT_TRUE(right.snapshot.camera_model.tested);
  EXPECT_FALSE(right.snapshot.camera_model.wrong) << right.snapshot.camera_model.message;
  EXPECT_GE(right.snapshot.remounts, 1) << right.snapshot.message;
  EXPECT_GE(right.broadcasts, 1);
}

}  // namespace
}  // namespace camera_imu_alignment
