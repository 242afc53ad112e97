# hybridctl_export: a plan's actions as programs (toolpaths + post-processor).
add_library(hybridctl_export STATIC plan_export.cpp)
target_link_libraries(hybridctl_export
  PUBLIC hybridctl_toolpaths hybridctl_gcode hybridctl_planner hybridctl_config hybridctl_geometry hybridctl_common
  PRIVATE hybridctl_warnings)
