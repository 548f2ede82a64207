"""dm-publish-map: publishes a speed-made-good map (the ROS map `dm-doe map` writes: <name>_ros.yaml, map_server's
format) as nav_msgs/OccupancyGrid, latched, for rviz and the navigation stack; map_server is not
packaged in Debian 12, so this node stands in for it and reads the file by map_server's rules
(dem_mobility_tools.doe.maps.load_ros_map: mode scale, a cell's occupancy 1 - speed / top speed, -1 without a
value).

    rosrun dem_mobility dm-publish-map results/map/physics_smg_ros.yaml [--frame map] [--topic map]
    roslaunch dem_mobility mobility_map.launch map:=$PWD/results/map/physics_smg_ros.yaml rviz:=true

Also publishes the map's metadata (nav_msgs/MapMetaData, `<topic>_metadata`, latched). The map
frame is the raster's CRS shifted so that the map's lower-left corner is at (0, 0) (the YAML's
`crs_origin` says where), which keeps rviz's float32 coordinates small; that shift is published
as a static transform from `<frame>_crs` (the CRS's own coordinates) to the map frame. Exits with status 2 and a
message naming the file when it cannot read it.
"""
import argparse
import sys



def occupancy_grid(loaded, frame, stamp):
    """The nav_msgs/OccupancyGrid of a map loaded by doe.maps.load_ros_map."""
    import math

    from geometry_msgs.msg import Pose
    from nav_msgs.msg import OccupancyGrid
    g = OccupancyGrid()
    g.header.frame_id = frame
    g.header.stamp = stamp
    g.info.map_load_time = stamp
    data = loaded['data']
    g.info.resolution = float(loaded['resolution'])
    g.info.height, g.info.width = int(data.shape[0]), int(data.shape[1])
    x, y, yaw = (float(v) for v in loaded['origin'])
    g.info.origin = Pose()
    g.info.origin.position.x, g.info.origin.position.y = x, y
    g.info.origin.orientation.z, g.info.origin.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    g.data = [int(v) for v in data.reshape(-1)]  # rows from the bottom, as load_ros_map gives them
    return g


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('map', help='the ROS map YAML (dm-doe map writes <name>_ros.yaml)')
    ap.add_argument('--frame', default='map', help='frame of the grid (default map)')
    ap.add_argument('--topic', default='map', help='topic (default map; also <topic>_metadata)')
    ap.add_argument('--crs-frame', default=None,
                    help='frame of the raster\'s CRS coordinates, the parent of the map frame on /tf_static '
                         '(translated by the YAML\'s crs_origin; default <frame>_crs)')
    a = ap.parse_args([x for x in (argv if argv is not None else sys.argv[1:]) if not x.startswith('__')])
    import yaml
    from ..doe.maps import load_ros_map
    try:
        loaded = load_ros_map(a.map)
    except (OSError, KeyError, ValueError, TypeError, yaml.YAMLError) as e:
        print('dm-publish-map: %s: cannot read the map (%s)' % (a.map, e), file=sys.stderr)
        return 2
    import rospy
    from nav_msgs.msg import MapMetaData, OccupancyGrid
    rospy.init_node('mobility_map')
    grid = occupancy_grid(loaded, a.frame, rospy.Time.now())
    pub = rospy.Publisher(a.topic, OccupancyGrid, queue_size=1, latch=True)
    meta = rospy.Publisher(a.topic + '_metadata', MapMetaData, queue_size=1, latch=True)
    pub.publish(grid)
    meta.publish(grid.info)
    # the map frame in the raster's CRS: a static transform (it also gives rviz its fixed frame)
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
    with open(a.map) as fh:
        crs_origin = (yaml.safe_load(fh) or {}).get('crs_origin') or [0.0, 0.0]
    t = TransformStamped()
    t.header.stamp = grid.header.stamp
    t.header.frame_id = a.crs_frame or a.frame + '_crs'
    t.child_frame_id = a.frame
    t.transform.translation.x, t.transform.translation.y = float(crs_origin[0]), float(crs_origin[1])
    t.transform.rotation.w = 1.0
    tf_static = rospy.Publisher('/tf_static', TFMessage, queue_size=1, latch=True)
    tf_static.publish(TFMessage(transforms=[t]))
    rospy.loginfo('dm-publish-map: %s: %d x %d cells of %g m on %s (frame %s)', a.map, grid.info.width,
                  grid.info.height, grid.info.resolution, rospy.resolve_name(a.topic), a.frame)
    rospy.spin()
    return 0


if __name__ == '__main__':
    sys.exit(main())
