# hybridctl_toolpaths: toolpaths from regions of influence (docs/toolpaths.md):
# raster deposition, Z-level pocket milling, and the part <-> work frame of a setup.
add_library(hybridctl_toolpaths STATIC
  ${CMAKE_CURRENT_LIST_DIR}/slices.cpp
  ${CMAKE_CURRENT_LIST_DIR}/setup_frame.cpp
  ${CMAKE_CURRENT_LIST_DIR}/deposition_path.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pocket_path.cpp
)
target_include_directories(hybridctl_toolpaths PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(hybridctl_toolpaths
  PUBLIC hybridctl_geometry hybridctl_config hybridctl_common
  PRIVATE hybridctl_warnings)
