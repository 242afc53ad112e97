# Tests of the G-code language library (parser, interpreter, checks, post-processor) and
# of our programs against LinuxCNC's rs274 (scripts/rs274, unpacked by scripts/setup).
hybridctl_test(gcode_language_tests
  SOURCES
    parser_test.cpp
    interpreter_test.cpp
    check_test.cpp
    post_test.cpp
    rs274_test.cpp
  LIBS hybridctl_gcode hybridctl_config)
