// Labels of the camera, IMU and target frames in rviz's 3D view, drawn by the alignment panel.
// rviz's TF display writes every frame's name centred on its origin, so the camera's and the IMU's
// (one origin: the broadcast tf has no translation) lie on top of each other. Here the camera's
// label sits above the origin and the IMU's below it, readable from any view; the TF display's
// own names are off in config/alignment.rviz. Runs on rviz's GUI (render) thread only.
#pragma once

#include <string>

namespace Ogre {
class SceneNode;
}
namespace rviz {
class DisplayContext;
class MovableText;
}  // namespace rviz

namespace camera_imu_alignment {

class FrameLabels {
 public:
  explicit FrameLabels(rviz::DisplayContext* context);
  ~FrameLabels();
  FrameLabels(const FrameLabels&) = delete;
  FrameLabels& operator=(const FrameLabels&) = delete;

  /// The frames to label ("" hides that label): tf frame names.
  void setFrames(const std::string& camera_frame, const std::string& imu_frame,
                 const std::string& target_frame);
  void setVisible(bool visible);

  /// Moves each label to its frame's origin in the fixed frame (latest tf); a frame tf does not
  /// know hides its label. Call once per rendered frame.
  void update();

  /// The IMU frame found in rviz's tf buffer next to `camera_frame` (findImuFrame); "" if none.
  std::string imuFrameFromTf(const std::string& camera_frame,
                             const std::string& target_frame) const;

 private:
  struct Label {
    std::string frame;
    Ogre::SceneNode* node = nullptr;
    rviz::MovableText* text = nullptr;
  };
  void setLabel(Label& label, const std::string& frame, const std::string& role);
  void place(Label& label);

  rviz::DisplayContext* context_;
  Ogre::SceneNode* root_ = nullptr;
  Label camera_, imu_, target_;
  bool visible_ = true;
};

}  // namespace camera_imu_alignment
