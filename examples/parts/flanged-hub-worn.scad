// A worn copy of flanged-hub.scad, to repair (`plan --stock`): the flange's top face has
// lost 2.5 mm over its half at x < 25 (z = 32.5 to 35 there), as a sliding contact wears
// it. The part's frame is the design's (mm). Regenerate with ./make-parts.
difference() {
  include <flanged-hub.scad>
  translate([-1, -1, 32.5]) cube([26, 52, 3]);
}
