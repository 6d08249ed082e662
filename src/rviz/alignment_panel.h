// rviz panel "camera_imu_alignment/AlignmentPanel" (rviz_plugins.xml): the alignment node's
// ~status (state, message, poses, residual, 1-sigma, the axis to rotate about next, IMU guidance,
// the latest and the broadcast estimate as roll, pitch, yaw, chi-square consistency, broadcast
// source), its ~stationary_poses as a list, and buttons for its services ~calibrate (with
// `force`), ~capture_pose, ~reset, ~save. The node is named by its namespace (default
// /camera_imu_alignment), saved in the rviz config with the frame-label switch.
//
// Threads: subscriptions run on rviz's GUI thread (rviz spins the global callback queue there);
// service calls run on their own threads (BackgroundCalls) and their answers are collected by a
// timer on the GUI thread, so a slow ~calibrate never freezes rviz. The text comes from
// panel_text.h (unit-tested without a display).
#pragma once

#include <geometry_msgs/PoseArray.h>
#include <ros/ros.h>
#include <rviz/panel.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera_imu_alignment/AlignmentStatus.h"
#include "camera_imu_alignment/rviz/background_calls.h"
#include "camera_imu_alignment/rviz/panel_text.h"

class QCheckBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QTableWidget;
class QTimer;

namespace camera_imu_alignment {

class FrameLabels;

class AlignmentPanel : public rviz::Panel {
  Q_OBJECT
 public:
  explicit AlignmentPanel(QWidget* parent = nullptr);
  ~AlignmentPanel() override;

  void onInitialize() override;
  void load(const rviz::Config& config) override;
  void save(rviz::Config config) const override;

 private Q_SLOTS:
  void onNamespaceEdited();
  void onCalibrate();
  void onCapturePose();
  void onReset();
  void onSave();
  void onTick();       ///< every 200 ms: service answers, button states, stale status, IMU frame
  void onPreUpdate();  ///< every rendered frame: the frame labels follow tf
  void onLabelsToggled(bool on);

 private:
  /// Subscribes to <namespace>/status and <namespace>/stationary_poses (after onInitialize).
  void subscribe();
  void applyNamespace(const QString& text);
  void onStatus(const AlignmentStatus::ConstPtr& status);
  void onPoses(const geometry_msgs::PoseArray::ConstPtr& poses);
  void showStatus(const StatusView& view);
  void showPoses(const std::vector<PoseRow>& rows);
  void showAnswer(const PanelRow& answer);
  void startTrigger(const std::string& service);
  std::string serviceName(const std::string& service) const;
  void updateButtons();

  std::string namespace_ = "/camera_imu_alignment";
  std::string namespace_error_;  ///< why the namespace typed last was refused ("" when not)
  bool initialized_ = false;
  ros::Subscriber status_sub_;
  ros::Subscriber poses_sub_;
  std::optional<ros::WallTime> last_status_;  ///< wall time of the latest ~status
  std::string camera_frame_;                  ///< the status header's frame_id
  std::string target_frame_ = "calibration_target";
  std::string imu_frame_;  ///< found in rviz's tf next to the camera frame
  int ticks_ = 0;

  BackgroundCalls calls_;
  std::unique_ptr<FrameLabels> labels_;

  QLineEdit* namespace_edit_;
  QLabel* state_label_;
  QLabel* message_label_;
  QLabel* notice_label_;  ///< stale status, a bad namespace
  QTableWidget* status_table_;
  QLabel* poses_caption_;
  QTableWidget* pose_table_;
  QPushButton* calibrate_button_;
  QCheckBox* force_check_;
  QPushButton* capture_button_;
  QPushButton* reset_button_;
  QPushButton* save_button_;
  QLabel* answer_label_;
  QCheckBox* labels_check_;
  QTimer* tick_timer_;
};

}  // namespace camera_imu_alignment
