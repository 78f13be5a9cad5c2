"""Shared by the rostests that must receive a topic from its first message (a module, not a test): waits
until a publisher of the topic lists this node's link in its slave API getBusInfo, the check of
include/sowing_robot/ros/common/publisher_links.h. A subscription merely made can lose the first messages
of a lockstep run that starts before its publisher has added the link."""
import time
import xmlrpc.client

import rosgraph
import rospy


def first_unlinked(topics):
    """The first of `topics` that no publisher has linked to this node yet, or None."""
    me = rospy.get_name()
    master = rosgraph.Master(me)
    publishers = dict(master.getSystemState()[0])
    for topic in topics:
        resolved = rospy.resolve_name(topic)
        linked = False
        for node in publishers.get(resolved, []):
            try:
                code, _, links = xmlrpc.client.ServerProxy(master.lookupNode(node)).getBusInfo(me)
            except (OSError, xmlrpc.client.Error, rosgraph.MasterException):
                continue  # gone or not answering: not linked
            linked = linked or (code == 1 and any(len(link) >= 5 and link[1] == me and link[2] == "o" and
                                                  link[4] == resolved for link in links))
        if not linked:
            return resolved
    return None


def wait_until_linked(topics, timeout):
    """None once every topic is linked; the first unlinked one after `timeout` s wall or on shutdown."""
    deadline = time.time() + timeout
    while True:
        missing = first_unlinked(topics)
        if missing is None or time.time() > deadline or rospy.is_shutdown():
            return missing
        time.sleep(0.01)
