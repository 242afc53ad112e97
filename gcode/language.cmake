# hybridctl_gcode: the G-code language (parser, modal interpreter, checks and time
# estimate, post-processor, LinuxCNC tool table). No OpenVDB: it uses geometry's plain
# Vec3 header only.
add_library(hybridctl_gcode STATIC
  ${CMAKE_CURRENT_LIST_DIR}/parser.cpp
  ${CMAKE_CURRENT_LIST_DIR}/interpreter.cpp
  ${CMAKE_CURRENT_LIST_DIR}/check.cpp
  ${CMAKE_CURRENT_LIST_DIR}/files.cpp
  ${CMAKE_CURRENT_LIST_DIR}/post.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tool_table.cpp
)
target_include_directories(hybridctl_gcode PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(hybridctl_gcode
  PUBLIC hybridctl_geometry hybridctl_config hybridctl_common
  PRIVATE hybridctl_warnings)
