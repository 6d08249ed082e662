// FrameLabels: rviz::MovableText on scene nodes placed from rviz's FrameManager (frame_labels.h).
#include "frame_labels.h"

#include <OgreSceneManager.h>
#include <OgreSceneNode.h>
#include <rviz/display_context.h>
#include <rviz/frame_manager.h>
#include <rviz/ogre_helpers/movable_text.h>

#include <map>
#include <vector>

#include "camera_imu_alignment/rviz/panel_text.h"

namespace camera_imu_alignment {

namespace {
constexpr float kCharacterHeight_m = 0.035f;  // about the size of the TF display's own names
constexpr float kLabelOffset_m = 0.03f;       // camera label this far above, IMU label below
}  // namespace

FrameLabels::FrameLabels(rviz::DisplayContext* context) : context_(context) {
  root_ = context_->getSceneManager()->getRootSceneNode()->createChildSceneNode();
}

FrameLabels::~FrameLabels() {
  for (Label* label : {&camera_, &imu_, &target_}) {
    if (label->node && label->text) label->node->detachObject(label->text);
    delete label->text;
  }
  root_->removeAndDestroyAllChildren();
  context_->getSceneManager()->destroySceneNode(root_);
}

void FrameLabels::setLabel(Label& label, const std::string& frame, const std::string& role) {
  if (label.frame == frame && (label.text || frame.empty())) return;
  label.frame = frame;
  if (!label.node) label.node = root_->createChildSceneNode();
  if (frame.empty()) {
    label.node->setVisible(false);
    return;
  }
  const std::string caption = role + ": " + frame;
  if (!label.text) {
    label.text = new rviz::MovableText(caption, "Liberation Sans", kCharacterHeight_m);
    label.text->showOnTop();  // drawn over the axes that cross it
    label.node->attachObject(label.text);
  } else {
    label.text->setCaption(caption);
  }
}

void FrameLabels::setFrames(const std::string& camera_frame, const std::string& imu_frame,
                            const std::string& target_frame) {
  setLabel(camera_, camera_frame, "camera");
  setLabel(imu_, imu_frame, "IMU");
  setLabel(target_, target_frame, "target");
  // Camera above its origin, IMU below the same origin (along the fixed frame's z, up in rviz's
  // usual views) with a gap between them: never on top of each other, clear of the axes' ends.
  if (camera_.text) {
    camera_.text->setTextAlignment(rviz::MovableText::H_CENTER, rviz::MovableText::V_ABOVE);
    camera_.text->setGlobalTranslation(Ogre::Vector3(0.0f, 0.0f, kLabelOffset_m));
  }
  if (imu_.text) {
    imu_.text->setTextAlignment(rviz::MovableText::H_CENTER, rviz::MovableText::V_BELOW);
    imu_.text->setGlobalTranslation(Ogre::Vector3(0.0f, 0.0f, -kLabelOffset_m));
  }
  if (target_.text)
    target_.text->setTextAlignment(rviz::MovableText::H_CENTER, rviz::MovableText::V_BELOW);
}

void FrameLabels::setVisible(bool visible) {
  visible_ = visible;
  root_->setVisible(visible);
}

void FrameLabels::place(Label& label) {
  if (!label.node) return;
  Ogre::Vector3 position;
  Ogre::Quaternion orientation;
  const bool known =
      !label.frame.empty() && label.text &&
      context_->getFrameManager()->getTransform(label.frame, ros::Time(), position, orientation);
  label.node->setVisible(visible_ && known);
  if (known) label.node->setPosition(position);
}

void FrameLabels::update() {
  for (Label* label : {&camera_, &imu_, &target_}) place(*label);
}

std::string FrameLabels::imuFrameFromTf(const std::string& camera_frame,
                                        const std::string& target_frame) const {
  const auto buffer = context_->getFrameManager()->getTF2BufferPtr();
  std::vector<std::string> frames;
  buffer->_getFrameStrings(frames);
  std::map<std::string, std::string> parent_of;
  for (const std::string& frame : frames) {
    std::string parent;
    if (buffer->_getParent(frame, ros::Time(), parent) && !parent.empty() && parent != frame)
      parent_of[frame] = parent;
  }
  return findImuFrame(camera_frame, target_frame, parent_of);
}

}  // namespace camera_imu_alignment
