# hybridctl_streaming: streaming a program over any Transport (drivers/transport.hpp),
# exactly once, and the job journal that lets a later run resume it.
add_library(hybridctl_streaming STATIC
  ${CMAKE_CURRENT_LIST_DIR}/streamer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/journal.cpp
)
target_include_directories(hybridctl_streaming PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(hybridctl_streaming
  PUBLIC hybridctl_protocol hybridctl_common
  PRIVATE hybridctl_warnings nlohmann_json::nlohmann_json Threads::Threads)
