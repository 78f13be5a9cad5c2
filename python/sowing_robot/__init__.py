"""sowing_robot for Python: analyze_bag (recorded runs), core (the C++ core: metrics, closed loop; pybind11),
msg and cfg (generated). Importable after `source devel/setup.bash`."""
