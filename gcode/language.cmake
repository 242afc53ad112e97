# hybridctl_gcode: the G-code language (parser, interpreter, post-processor, checks).
add_library(hybridctl_gcode INTERFACE)
target_include_directories(hybridctl_gcode INTERFACE ${PROJECT_SOURCE_DIR})
target_link_libraries(hybridctl_gcode INTERFACE hybridctl_geometry hybridctl_config hybridctl_common)
