// The rviz markers the nodes publish (coverage_topics, reference_generator's field, plant_sim's soil patches, the
// seed drill's seeds), set up in one way: the frame, stamp, namespace, id, type, scale, colour and lifetime of a
// marker to ADD, and the DELETEALL that clears a namespace set before a latched array is sent again.
#pragma once

#include <ros/time.h>
#include <visualization_msgs/Marker.h>

#include <string>

namespace sowing_robot {

/// What a marker looks like: its type (visualization_msgs::Marker::CYLINDER, LINE_STRIP, ...), colour and scale (a
/// line's width is scale x; 0 where the type reads none).
struct MarkerLook {
  int type;
  float r, g, b, a;
  double scale_x, scale_y = 0.0, scale_z = 0.0;
};

/// A marker to ADD in `frame`: ns, id, the look, the identity orientation at the origin. Stamp 0 by default: rviz then
/// draws it with the latest transform (the frames are world-fixed); lifetime 0: it stays until replaced or deleted.
visualization_msgs::Marker rvizMarker(const std::string& frame, const std::string& ns, int id, const MarkerLook& look,
                                      const ros::Time& stamp = ros::Time(),
                                      const ros::Duration& lifetime = ros::Duration());

/// A DELETEALL in `frame`: first in a re-published array, so that the new set replaces the old one whole.
visualization_msgs::Marker deleteAllMarker(const std::string& frame);

}  // namespace sowing_robot
