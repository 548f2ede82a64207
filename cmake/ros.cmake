# The ROS layer: messages of the lock-step exchange and results, and the catkin package. The core
# (src/core) never sees any of this; nodelets (later) link dm_core and the generated messages.
find_package(catkin REQUIRED COMPONENTS roscpp std_msgs geometry_msgs message_generation)

add_message_files(DIRECTORY msg FILES
  WheelStates.msg
  WheelWrenches.msg
  DriverCommand.msg
  MobilityResult.msg
)
generate_messages(DEPENDENCIES std_msgs geometry_msgs)

catkin_package(
  INCLUDE_DIRS include
  CATKIN_DEPENDS roscpp std_msgs geometry_msgs message_runtime
)
