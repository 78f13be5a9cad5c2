#include "sowing_robot/ros/common/markers.h"

namespace sowing_robot {

visualization_msgs::Marker rvizMarker(const std::string& frame, const std::string& ns, int id, const MarkerLook& look,
                                      const ros::Time& stamp, const ros::Duration& lifetime) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = look.type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = look.scale_x;
  m.scale.y = look.scale_y;
  m.scale.z = look.scale_z;
  m.color.r = look.r;
  m.color.g = look.g;
  m.color.b = look.b;
  m.color.a = look.a;
  m.lifetime = lifetime;
  return m;
}

visualization_msgs::Marker deleteAllMarker(const std::string& frame) {
  visualization_msgs::Marker clear;
  clear.header.frame_id = frame;
  clear.action = visualization_msgs::Marker::DELETEALL;
  return clear;
}

}  // namespace sowing_robot
