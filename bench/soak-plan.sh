# Sourced by bench/soak and bench/soak-hard (not a bench script of its own): the soak's
# job, planned and exported once.
#
#   soak_name=soak; soak_plan HYBRIDCTL PART MACHINE VOXEL RANK WORK
#
# Plans PART on MACHINE at VOXEL mm into WORK/plan (kept: a later call with the same WORK,
# part, machine and voxel size reuses it) and exports plan RANK to
# WORK/export/plan-RANK.ngc. RANK `auto`: the best plan that deposits and mills, with
# at least two tools or heads and two setups (12 plans are searched); the rank chosen is
# left in the caller's `plan_rank`. When the part has no plan, no plan RANK or no plan of
# that kind, it prints why (plan's own verdict and reasons) on stderr and returns 1.
# Otherwise it prints what the program holds: lines, actions (deposition and milling),
# tool changes and program stops (setup changes by hand).

soak_plan() {
  local hybridctl=$1 part=$2 machine=$3 voxel=$4 rank=$5 work=$6 code top
  local key="$part $machine $voxel" name=${soak_name:-soak}
  if [ ! -f "$work/plan/plan.json" ] || [ "$(cat "$work/plan.key" 2>/dev/null)" != "$key" ]; then
    rm -rf "$work/plan" "$work/export" "$work/plan.key"
    if [ "$rank" = auto ]; then top=12; else top=$(( rank > 3 ? rank : 3 )); fi
    set +e
    "$hybridctl" plan "$part" --machine "$machine" --voxel "$voxel" --top "$top" -o "$work/plan" >"$work/plan.log" 2>&1
    code=$?
    set -e
    if [ "$code" != 0 ]; then
      echo "$name: cannot plan $part on $machine at $voxel mm: \`hybridctl plan\` exited $code" \
           "($( [ "$code" = 4 ] && echo "not manufacturable, or no plan makes the part when executed" || echo "see below" )):" >&2
      grep -v '^\s*$' "$work/plan.log" | grep -E '^(verdict|validated|  x |hybridctl:)' | head -n 12 | cut -c1-240 | sed 's/^/  /' >&2
      echo "$name: pick another part, machine or voxel size (--part, --machine, --voxel); $work/plan.log has it all" >&2
      return 1
    fi
    echo "$key" >"$work/plan.key"
  fi
  if [ "$rank" = auto ]; then
    rank=$(/usr/bin/python3 - "$work/plan/plan.json" <<'PY'
import json, sys
plan = json.load(open(sys.argv[1]))
primitives = {p["name"]: p for p in plan["primitives"]}
for p in plan["plans"]:
    steps = [primitives[a["primitive"]] for a in p["actions"] if primitives[a["primitive"]]["kind"] != "raw-stock"]
    deposits = any(s["mode"] == "additive" for s in steps)
    mills = any(s["mode"] == "subtractive" for s in steps)
    if deposits and mills and len({s["capability"] for s in steps}) >= 2 and len({s["setup"] for s in steps}) >= 2:
        print(p["rank"])
        break
PY
)
    if [ -z "$rank" ]; then
      echo "$name: none of the plans of $part on $machine at $voxel mm both deposits" \
           "and mills with two tools or heads in two setups; name one with --plan RANK" >&2
      return 1
    fi
  fi
  plan_rank=$rank
  local program="$work/export/plan-$rank.ngc"
  if [ ! -f "$program" ]; then
    set +e
    "$hybridctl" export "$work/plan" --plan "$rank" -o "$work/export" >>"$work/plan.log" 2>&1
    code=$?
    set -e
    if [ "$code" != 0 ] || [ ! -f "$program" ]; then
      echo "$name: cannot export plan $rank of $part on $machine at $voxel mm (export exited $code):" >&2
      tail -n 5 "$work/plan.log" | sed 's/^/  /' >&2
      echo "$name: pick another --plan (plan.log lists the plans)" >&2
      return 1
    fi
  fi
  local lines actions additive milling tools stops
  lines=$(wc -l <"$program")
  actions=$(grep -c '^(action [0-9]*:' "$program" || true)
  additive=$(grep -c '^(action [0-9]*:.*additive' "$program" || true)
  milling=$(grep -c '^(action [0-9]*:.*subtractive' "$program" || true)
  tools=$(grep -Ec '(^|[^0-9A-Z])M0?6([^0-9]|$)' "$program" || true)
  stops=$(grep -Ec '(^|[^0-9A-Z])M0?[01]([^0-9]|$)' "$program" || true)
  # What finishing passes bring (issue 42: a program with arcs and many short moves): arcs,
  # and feed moves under 0.5 mm (from the previous programmed X and Y).
  local arcs short
  arcs=$(grep -Ec '(^|[^0-9A-Z.])G0?[23]([^0-9]|$)' "$program" || true)
  short=$(awk '{ x = px; y = py; for (i = 1; i <= NF; ++i) { if ($i ~ /^X-?[0-9.]+$/) x = substr($i, 2) + 0;
                 if ($i ~ /^Y-?[0-9.]+$/) y = substr($i, 2) + 0 }
                 if ($1 == "G1" && (x - px) ^ 2 + (y - py) ^ 2 < 0.25 && (x != px || y != py)) ++n; px = x; py = y }
               END { print n + 0 }' "$program")
  echo "$name: the job: plan $rank, $lines lines: $actions actions ($additive deposition, $milling milling), $tools tool changes, $stops program stops, $arcs arcs, $short feed moves under 0.5 mm"
}
