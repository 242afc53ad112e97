#pragma once
// Replaying a G-code program on a voxel stock: the modal interpreter (gcode/) says what
// the machine does, motion by motion; the material simulation (sim/material.hpp) does it
// to the stock. It is how exported programs are checked against their plan, and what the
// machine simulator runs.
//
// Frames: the stock is given and returned in the part frame. Each motion runs in the
// work frame of the setup whose work offset is active (G54..G59 -> the machine's setup
// with that work_offset; its approach turns part into work frame, its work_origin places
// work zero on the machine). G53 moves are taken relative to the last active setup.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/machine.hpp"
#include "geometry/solid.hpp"
#include "sim/material.hpp"

namespace hybridctl::sim {

struct ReplayOptions {
  // Voxels that must not be removed (part frame), e.g. the design shrunk by its tolerance.
  std::optional<geometry::Solid> protected_region;
  SimulationOptions simulation;
};

struct ReplayResult {
  geometry::Solid stock;         // part frame, on the start stock's lattice and domain
  SimulationReport report;       // summed over the program; incidents carry G-code lines
  std::vector<std::string> errors;  // G-code errors (the line is skipped), "FILE:line:col: ..."
  int lines = 0;
  int motions = 0;
  int simulated = 0;             // motions that moved a tool or head
};

// Throws InputError only when the machine's deposition codes are unusable; bad lines are
// reported in `errors` and skipped. The stock's storage box is the simulated domain.
ReplayResult replay_program(std::string_view text, const config::Machine& machine, const geometry::Solid& stock,
                            const ReplayOptions& options = {}, const std::string& file_name = "<gcode>");

}  // namespace hybridctl::sim
