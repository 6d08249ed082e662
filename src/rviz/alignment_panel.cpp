// AlignmentPanel: widgets, subscriptions and service buttons (see alignment_panel.h).
#include "alignment_panel.h"

#include <rviz/visualization_manager.h>
#include <std_srvs/Trigger.h>
#include <pluginlib/class_list_macros.hpp>

#include <QCheckBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMessageBox>
#include <QPushButton>
#include <QTableWidget>
#include <QTimer>
#include <QVBoxLayout>

#include "camera_imu_alignment/Calibrate.h"
#include "frame_labels.h"

namespace camera_imu_alignment {

namespace {

constexpr int kTickPeriod_ms = 200;
constexpr int kServiceWait_ms = 1000;    // a service not advertised within this is unreachable
constexpr double kStatusStale_s = 3.0;   // the node publishes ~status at least once per second
constexpr int kImuFrameSearchTicks = 5;  // look for the IMU frame in tf once per second

QString qt(const std::string& text) { return QString::fromStdString(text); }

QColor colourOf(RowLevel level) {
  switch (level) {
    case RowLevel::kGood:
      return QColor(27, 128, 47);
    case RowLevel::kWarning:
      return QColor(176, 104, 0);
    case RowLevel::kError:
      return QColor(198, 40, 40);
    case RowLevel::kNormal:
      break;
  }
  return QColor();
}

/// Text in the level's colour (a label's style sheet); plain for kNormal.
void styleLabel(QLabel* label, RowLevel level, bool as_badge) {
  const QColor colour = colourOf(level);
  if (!colour.isValid()) {
    label->setStyleSheet(as_badge ? "font-weight: bold; padding: 2px;" : "");
  } else if (as_badge) {
    label->setStyleSheet(QString("font-weight: bold; padding: 2px; color: white; "
                                 "background-color: %1;")
                             .arg(colour.name()));
  } else {
    label->setStyleSheet(QString("color: %1;").arg(colour.name()));
  }
}

QTableWidget* makeTable(int columns, const QStringList& headers) {
  auto* table = new QTableWidget(0, columns);
  table->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table->setSelectionMode(QAbstractItemView::ContiguousSelection);
  table->setWordWrap(true);
  table->verticalHeader()->hide();
  table->horizontalHeader()->setStretchLastSection(true);
  if (headers.isEmpty()) {
    table->horizontalHeader()->hide();
  } else {
    table->setHorizontalHeaderLabels(headers);
  }
  return table;
}

QTableWidgetItem* item(const std::string& text, RowLevel level = RowLevel::kNormal,
                       const std::string& tooltip = "") {
  auto* cell = new QTableWidgetItem(qt(text));
  const QColor colour = colourOf(level);
  if (colour.isValid()) cell->setForeground(colour);
  if (!tooltip.empty()) cell->setToolTip(qt(tooltip));
  return cell;
}

}  // namespace

AlignmentPanel::AlignmentPanel(QWidget* parent) : rviz::Panel(parent) {
  namespace_edit_ = new QLineEdit(qt(namespace_));
  namespace_edit_->setToolTip(
      "namespace of the alignment node: its ~status, ~stationary_poses "
      "and services are found under it");
  state_label_ = new QLabel("(no status yet)");
  styleLabel(state_label_, RowLevel::kNormal, true);
  message_label_ = new QLabel;
  message_label_->setWordWrap(true);
  message_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  notice_label_ = new QLabel;
  notice_label_->setWordWrap(true);
  notice_label_->hide();
  status_table_ = makeTable(2, {});
  poses_caption_ =
      new QLabel(qt("Poses in the window: the camera in the target frame "
                    "(R_target_cam), " +
                    std::string(kRpyConvention) + "; turn from the previous pose"));
  poses_caption_->setWordWrap(true);
  pose_table_ = makeTable(6, {"#", "roll", "pitch", "yaw", "turn", "position (m)"});
  calibrate_button_ = new QPushButton("Calibrate");
  calibrate_button_->setToolTip("~calibrate: solve now on the window of poses");
  force_check_ = new QCheckBox("force");
  force_check_->setToolTip("broadcast (and save) the estimate even if it fails the quality gates");
  capture_button_ = new QPushButton("Capture pose");
  capture_button_->setToolTip("~capture_pose: with manual_capture, make the next rest a pose");
  reset_button_ = new QPushButton("Reset");
  reset_button_->setToolTip("~reset: forget the poses and start over");
  save_button_ = new QPushButton("Save");
  save_button_->setToolTip("~save: write the broadcast calibration to the node's output file");
  answer_label_ = new QLabel("Service answers appear here.");
  answer_label_->setWordWrap(true);
  answer_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  labels_check_ = new QCheckBox("label camera, IMU and target frames in the 3D view");
  labels_check_->setChecked(true);

  auto* namespace_row = new QHBoxLayout;
  namespace_row->addWidget(new QLabel("node"));
  namespace_row->addWidget(namespace_edit_, 1);
  auto* calibrate_row = new QHBoxLayout;
  calibrate_row->addWidget(calibrate_button_, 1);
  calibrate_row->addWidget(force_check_);
  calibrate_row->addWidget(capture_button_, 1);
  auto* other_row = new QHBoxLayout;
  other_row->addWidget(reset_button_, 1);
  other_row->addWidget(save_button_, 1);
  auto* layout = new QVBoxLayout;
  layout->addLayout(namespace_row);
  layout->addWidget(state_label_);
  layout->addWidget(message_label_);
  layout->addWidget(notice_label_);
  layout->addWidget(status_table_, 3);
  layout->addWidget(poses_caption_);
  layout->addWidget(pose_table_, 2);
  layout->addLayout(calibrate_row);
  layout->addLayout(other_row);
  layout->addWidget(answer_label_);
  layout->addWidget(labels_check_);
  setLayout(layout);

  connect(namespace_edit_, SIGNAL(editingFinished()), this, SLOT(onNamespaceEdited()));
  connect(calibrate_button_, SIGNAL(clicked()), this, SLOT(onCalibrate()));
  connect(capture_button_, SIGNAL(clicked()), this, SLOT(onCapturePose()));
  connect(reset_button_, SIGNAL(clicked()), this, SLOT(onReset()));
  connect(save_button_, SIGNAL(clicked()), this, SLOT(onSave()));
  connect(labels_check_, SIGNAL(toggled(bool)), this, SLOT(onLabelsToggled(bool)));
  // Wrapped cells need their row heights again when the column width changes.
  connect(status_table_->horizontalHeader(), &QHeaderView::sectionResized, status_table_,
          &QTableWidget::resizeRowsToContents);
  tick_timer_ = new QTimer(this);
  connect(tick_timer_, SIGNAL(timeout()), this, SLOT(onTick()));
}

AlignmentPanel::~AlignmentPanel() = default;

void AlignmentPanel::onInitialize() {
  initialized_ = true;
  labels_ = std::make_unique<FrameLabels>(vis_manager_);
  labels_->setVisible(labels_check_->isChecked());
  labels_->setFrames(camera_frame_, imu_frame_, target_frame_);
  connect(vis_manager_, SIGNAL(preUpdate()), this, SLOT(onPreUpdate()));
  subscribe();
  tick_timer_->start(kTickPeriod_ms);
}

void AlignmentPanel::load(const rviz::Config& config) {
  rviz::Panel::load(config);
  QString name_space;
  if (config.mapGetString("Namespace", &name_space)) {
    namespace_edit_->setText(name_space);
    applyNamespace(name_space);
  }
  bool labels = true;
  if (config.mapGetBool("Frame labels", &labels)) labels_check_->setChecked(labels);
}

void AlignmentPanel::save(rviz::Config config) const {
  rviz::Panel::save(config);
  config.mapSetValue("Namespace", qt(namespace_));
  config.mapSetValue("Frame labels", labels_check_->isChecked());
}

void AlignmentPanel::onNamespaceEdited() { applyNamespace(namespace_edit_->text()); }

void AlignmentPanel::applyNamespace(const QString& text) {
  std::string error;
  const std::optional<std::string> name_space = normalizeNamespace(text.toStdString(), &error);
  if (!name_space) {
    namespace_error_ = error + "; still listening to " + namespace_;
    onTick();
    return;
  }
  namespace_error_.clear();
  namespace_edit_->setText(qt(*name_space));
  if (*name_space == namespace_ && (status_sub_ || !initialized_)) return;
  namespace_ = *name_space;
  Q_EMIT configChanged();
  subscribe();
}

void AlignmentPanel::subscribe() {
  if (!initialized_) return;
  status_sub_.shutdown();
  poses_sub_.shutdown();
  last_status_.reset();
  status_table_->setRowCount(0);
  pose_table_->setRowCount(0);
  state_label_->setText("(no status yet)");
  styleLabel(state_label_, RowLevel::kNormal, true);
  message_label_->clear();
  ros::NodeHandle nh;
  status_sub_ = nh.subscribe(namespace_ + "/status", 10, &AlignmentPanel::onStatus, this);
  poses_sub_ = nh.subscribe(namespace_ + "/stationary_poses", 1, &AlignmentPanel::onPoses, this);
  onTick();
}

void AlignmentPanel::onStatus(const AlignmentStatus::ConstPtr& status) {
  last_status_ = ros::WallTime::now();
  if (!status->header.frame_id.empty() && status->header.frame_id != camera_frame_) {
    camera_frame_ = status->header.frame_id;
    if (labels_) labels_->setFrames(camera_frame_, imu_frame_, target_frame_);
  }
  showStatus(describeStatus(*status));
}

void AlignmentPanel::onPoses(const geometry_msgs::PoseArray::ConstPtr& poses) {
  if (!poses->header.frame_id.empty() && poses->header.frame_id != target_frame_) {
    target_frame_ = poses->header.frame_id;
    if (labels_) labels_->setFrames(camera_frame_, imu_frame_, target_frame_);
  }
  showPoses(describePoses(*poses));
}

void AlignmentPanel::showStatus(const StatusView& view) {
  state_label_->setText(qt(view.state));
  styleLabel(state_label_, view.state_level, true);
  message_label_->setText(qt(view.message));
  status_table_->setRowCount(static_cast<int>(view.rows.size()));
  for (int i = 0; i < static_cast<int>(view.rows.size()); ++i) {
    const PanelRow& row = view.rows[i];
    status_table_->setItem(i, 0, item(row.label, RowLevel::kNormal, row.tooltip));
    status_table_->setItem(i, 1, item(row.value, row.level, row.tooltip));
  }
  status_table_->resizeColumnToContents(0);
  status_table_->resizeRowsToContents();
}

void AlignmentPanel::showPoses(const std::vector<PoseRow>& rows) {
  pose_table_->setRowCount(static_cast<int>(rows.size()));
  for (int i = 0; i < static_cast<int>(rows.size()); ++i) {
    const PoseRow& row = rows[i];
    const RowLevel level = row.valid ? RowLevel::kNormal : RowLevel::kError;
    const std::string cells[] = {row.index,   row.roll_deg, row.pitch_deg,
                                 row.yaw_deg, row.turn_deg, row.position_m};
    for (int column = 0; column < 6; ++column) {
      QTableWidgetItem* cell = item(cells[column], level);
      if (column < 5) cell->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
      pose_table_->setItem(i, column, cell);
    }
  }
  pose_table_->resizeColumnsToContents();
  pose_table_->resizeRowsToContents();
  pose_table_->scrollToBottom();  // the newest pose
}

void AlignmentPanel::showAnswer(const PanelRow& answer) {
  answer_label_->setText(qt(answer.label + ": " + answer.value));
  styleLabel(answer_label_, answer.level, false);
}

std::string AlignmentPanel::serviceName(const std::string& service) const {
  return namespace_ + "/" + service;
}

void AlignmentPanel::onCalibrate() {
  const std::string name = serviceName("calibrate");
  Calibrate call;
  call.request.force = force_check_->isChecked();
  calls_.start("calibrate", [name, call]() mutable {
    if (!ros::service::waitForService(name, kServiceWait_ms))
      return describeUnreachable(name, false);
    if (!ros::service::call(name, call)) return describeUnreachable(name, true);
    return describeCalibrateAnswer(call.request, call.response);
  });
  force_check_->setChecked(false);  // forcing is for one call, not a mode left on
  updateButtons();
}

void AlignmentPanel::startTrigger(const std::string& service) {
  const std::string name = serviceName(service);
  calls_.start(service, [name, service]() {
    std_srvs::Trigger call;
    if (!ros::service::waitForService(name, kServiceWait_ms))
      return describeUnreachable(name, false);
    if (!ros::service::call(name, call)) return describeUnreachable(name, true);
    return describeTriggerAnswer(service, call.response);
  });
  updateButtons();
}

void AlignmentPanel::onCapturePose() { startTrigger("capture_pose"); }

void AlignmentPanel::onReset() {
  const QMessageBox::StandardButton answer = QMessageBox::question(
      this, "Reset the alignment",
      qt("Forget the stationary poses of " + namespace_ + " and start over?"));
  if (answer == QMessageBox::Yes) startTrigger("reset");
}

void AlignmentPanel::onSave() { startTrigger("save"); }

void AlignmentPanel::updateButtons() {
  const std::pair<QPushButton*, const char*> buttons[] = {{calibrate_button_, "calibrate"},
                                                          {capture_button_, "capture_pose"},
                                                          {reset_button_, "reset"},
                                                          {save_button_, "save"}};
  std::string waiting;
  for (const auto& [button, service] : buttons) {
    const bool pending = calls_.pending(service);
    button->setEnabled(!pending);
    if (pending)
      waiting += std::string(waiting.empty() ? "" : "; ") + service + ": waiting for the answer (" +
                 std::to_string(static_cast<int>(calls_.pendingSeconds(service))) + " s)";
  }
  if (!waiting.empty()) {
    answer_label_->setText(qt(waiting));
    styleLabel(answer_label_, RowLevel::kNormal, false);
  }
}

void AlignmentPanel::onTick() {
  for (const BackgroundCalls::Finished& finished : calls_.takeFinished())
    showAnswer(finished.answer);
  updateButtons();
  const double age_s = last_status_ ? (ros::WallTime::now() - *last_status_).toSec() : -1.0;
  const std::string notice = !namespace_error_.empty()
                                 ? namespace_error_
                                 : statusAgeText(namespace_ + "/status", age_s, kStatusStale_s);
  if (notice.empty()) {
    notice_label_->hide();
  } else {
    notice_label_->setText(qt(notice));
    styleLabel(notice_label_, namespace_error_.empty() ? RowLevel::kWarning : RowLevel::kError,
               false);
    notice_label_->show();
  }
  if (labels_ && ++ticks_ % kImuFrameSearchTicks == 0) {
    const std::string imu_frame = labels_->imuFrameFromTf(camera_frame_, target_frame_);
    if (imu_frame != imu_frame_) {
      imu_frame_ = imu_frame;
      labels_->setFrames(camera_frame_, imu_frame_, target_frame_);
    }
  }
}

void AlignmentPanel::onPreUpdate() {
  if (labels_) labels_->update();
}

void AlignmentPanel::onLabelsToggled(bool on) {
  if (labels_) labels_->setVisible(on);
  Q_EMIT configChanged();
}

}  // namespace camera_imu_alignment

PLUGINLIB_EXPORT_CLASS(camera_imu_alignment::AlignmentPanel, rviz::Panel)
