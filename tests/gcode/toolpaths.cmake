# Tests of hybridctl_toolpaths (gcode/toolpaths.cmake): included by tests/gcode/CMakeLists.txt.
hybridctl_test(setup_frame_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/setup_frame_test.cpp
  LIBS hybridctl_toolpaths hybridctl_geometry hybridctl_config)
hybridctl_test(deposition_path_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/deposition_path_test.cpp
  LIBS hybridctl_toolpaths hybridctl_geometry hybridctl_config)
hybridctl_test(pocket_path_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/pocket_path_test.cpp
  LIBS hybridctl_toolpaths hybridctl_planner hybridctl_geometry hybridctl_config)
hybridctl_test(toolpath_plan_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/toolpath_plan_test.cpp
  LIBS hybridctl_toolpaths hybridctl_planner hybridctl_geometry hybridctl_config)
hybridctl_test(toolpath_sim_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/toolpath_sim_test.cpp
  LIBS hybridctl_toolpaths hybridctl_sim hybridctl_geometry hybridctl_config)
