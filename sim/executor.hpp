#pragma once
// Executing G-code line by line on a simulated machine: the modal interpreter (gcode/)
// says what the machine does; the checks a real controller makes come first (soft
// limits, tools in the magazine, process interlocks); the material simulation
// (sim/material.hpp) then does it to the stock. sim::replay_program and the simulated
// controller (sim/controller.hpp) both run on it.
//
// Frames: the stock is kept in the part frame. Each motion runs in the work frame of the
// setup whose work offset is active (G54..G59 -> the machine's setup with that
// work_offset; its approach turns part into work frame, its work_origin places work zero
// on the machine). G53 moves are taken relative to the last active setup.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/machine.hpp"
#include "gcode/interpreter.hpp"
#include "geometry/solid.hpp"
#include "sim/material.hpp"

namespace hybridctl::sim {

struct ExecutorOptions {
  // The material at the start (part frame); its storage box is the simulated world.
  // Without one, motions are checked and timed but nothing is cut or deposited.
  std::optional<geometry::Solid> stock;
  // Voxels that must not be removed (part frame), e.g. the design shrunk by its tolerance.
  std::optional<geometry::Solid> protected_region;
  SimulationOptions simulation;
};

// Why a line stopped the machine, as a controller would say it.
enum class Stop {
  None,
  GcodeError,                 // the line is not valid G-code: not executed
  EnvelopeViolation,          // a motion would leave the travel: stopped before it
  ToolNotInMagazine,          // M6 of a tool (or head) the machine does not have
  DepositionWithoutHead,      // a deposition code with a cutting tool (or none) in the spindle
  SpindleDepositionConflict,  // spindle and deposition on together
  RapidIntoMaterial,          // a rapid met material (after it happened)
  NozzleCollision,            // a head's feed move touched material with the nozzle body (after it happened)
};

struct LineOutcome {
  std::vector<gcode::Motion> motions;  // those executed
  std::vector<gcode::Event> events;
  double seconds = 0;                  // virtual time: motions (trapezoidal) and dwells
  std::vector<Incident> incidents;     // from the material simulation
  Stop stop = Stop::None;
  std::string message;                 // what stopped it, with the line
};

class ProgramExecutor {
  struct Impl;

 public:
  ProgramExecutor(const config::Machine& machine, std::string file_name, ExecutorOptions options = {},
                  gcode::InterpreterOptions interpreter = {});
  ~ProgramExecutor();
  ProgramExecutor(ProgramExecutor&&) noexcept;
  ProgramExecutor& operator=(ProgramExecutor&&) noexcept;

  // Executes one line. A line that is not valid G-code, trips an interlock (tool,
  // deposition, spindle) or would leave the envelope is refused whole: the machine stays
  // as it was before it.
  LineOutcome execute_line(std::string_view text, int number);

  // The voxels cuts must spare from the next line on (part frame), in place of
  // ExecutorOptions::protected_region: validation protects per action what that action
  // keeps of the design (plan/start_stock.hpp).
  void set_protected_region(std::optional<geometry::Solid> protected_region);

  const gcode::ModalState& state() const;
  // The stock now (part frame); empty solid when there is no stock.
  geometry::Solid stock() const;
  // Totals over everything executed so far.
  SimulationReport report() const;

  // Everything the executor holds after the lines so far (interpreter, stock, active
  // frame, protected region, report), to go on from later (validation/ resumes plans from
  // a prefix it executed before). Its machine is kept by reference, as the executor's.
  class Snapshot {
   public:
    Snapshot();
    ~Snapshot();
    Snapshot(Snapshot&&) noexcept;
    Snapshot& operator=(Snapshot&&) noexcept;
    // Estimated memory, bytes: mostly the voxel solids.
    std::size_t bytes() const;

   private:
    friend class ProgramExecutor;
    std::unique_ptr<Impl> impl_;
  };
  Snapshot snapshot() const;
  // An executor that goes on from `snapshot` exactly as the one it was taken from would.
  explicit ProgramExecutor(const Snapshot& snapshot);

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace hybridctl::sim
