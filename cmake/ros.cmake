# The ROS layer: messages of the lock-step exchange and results, the nodelets (thin wrappers over
# dm_core), launch files and ROS tests. The core (src/core) never sees any of this.
find_package(catkin REQUIRED COMPONENTS geometry_msgs message_generation nav_msgs nodelet pluginlib rosbag
  rosgraph_msgs roscpp sensor_msgs std_msgs tf2_msgs topic_tools visualization_msgs)
# the Python package dem_mobility_tools (setup.py, python/) on the workspace's PYTHONPATH, devel and install
catkin_python_setup()

add_message_files(DIRECTORY msg FILES
  WheelStates.msg
  WheelWrenches.msg
  DriverInput.msg
  DriverCommand.msg
  MobilityResult.msg
  ConePenetration.msg
  ConeIndexResult.msg
  WheelRigSample.msg
  SingleWheelResult.msg
)
add_service_files(DIRECTORY srv FILES
  TerrainReport.srv
)
generate_messages(DEPENDENCIES std_msgs geometry_msgs)

catkin_package(
  INCLUDE_DIRS include
  LIBRARIES ${PROJECT_NAME}_nodelets
  CATKIN_DEPENDS geometry_msgs message_runtime nav_msgs nodelet pluginlib rosbag rosgraph_msgs roscpp sensor_msgs std_msgs
    tf2_msgs topic_tools visualization_msgs
)
install(DIRECTORY include/${PROJECT_NAME}/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})
# its console scripts (pyproject.toml) as programs of the package: rosrun dem_mobility dm-doe ..., and
# the nodes of the launch files (mobility_map.launch: dm-publish-map)
catkin_install_python(PROGRAMS
  python/bin/dm-doe
  python/bin/dm-calibrate
  python/bin/dm-wheel-sweep
  python/bin/dm-fidelity-study
  python/bin/dm-plot-fidelity
  python/bin/dm-stability
  python/bin/dm-publish-map
  python/bin/dm-bench-doe-map
  python/bin/dm-plot-speed
  python/bin/dm-plot-compression
  python/bin/dm-driveshaft-curves
  python/bin/dm-launch
  python/bin/dm-docs
  python/bin/dm-docs-cone
  python/bin/dm-docs-wheel
  python/bin/dm-docs-cone-setup
  DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  find_package(roslaunch REQUIRED)
  # every launch file parses and finds its packages and files
  roslaunch_add_file_check(launch/road_slope.launch)
  roslaunch_add_file_check(launch/soil_slope.launch)
  roslaunch_add_file_check(launch/cone_penetrometer.launch)
  roslaunch_add_file_check(launch/single_wheel.launch)
  roslaunch_add_file_check(launch/replay.launch bag:=/tmp/run.bag)
  roslaunch_add_file_check(launch/components/vehicle.launch)
  roslaunch_add_file_check(launch/components/terrain.launch)
  roslaunch_add_file_check(launch/components/soil_rig.launch)
  roslaunch_add_file_check(launch/components/driver.launch)
  roslaunch_add_file_check(launch/components/recorder.launch bag:=/tmp/run.bag)
  roslaunch_add_file_check(launch/bench/cosim_exchange.launch)
  roslaunch_add_file_check(launch/mobility_map.launch map:=/tmp/map.yaml)
  roslaunch_add_file_check(test/ros/road_scene.test)
  add_rostest(test/ros/road_scene.test)
endif()
