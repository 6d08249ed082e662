// sim_time_guard: started by launch/replay_bag.launch beside the player. roslaunch sets
// /use_sim_time for the replay and never unsets it: on a roscore that outlives the launch, every
// node started later would wait for a /clock that no longer comes. This node does nothing until
// it is stopped (Ctrl-C on the launch: SIGINT, or SIGTERM), then deletes /use_sim_time (absent
// means wall time) while it can still reach the master.
#include <ros/ros.h>

#include <csignal>
#include <cstdio>

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "sim_time_guard", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh;
  while (!g_stop && ros::ok()) ros::WallDuration(0.1).sleep();
  if (ros::param::has("/use_sim_time") && ros::param::del("/use_sim_time")) {
    std::printf("sim_time_guard: /use_sim_time deleted (the replay is over: wall time again)\n");
  }
  ros::shutdown();
  return 0;
}
