// A 50 x 50 x 6 plate with a round tube standing on its middle: 20 mm across, a 2.5 mm
// wall (bore 15 mm), 24 mm tall (z = 6..30). A part to mill from a block, whose bore's
// round face no cutter's voxels follow exactly: on a 0.5 mm grid only toolpaths on the
// real surface make it within a tolerance under a voxel (docs/plan-format.md,
// "Tolerance and band").
// Regenerate with ./make-parts.
$fn = 48;
union() {
  cube([50, 50, 6]);
  translate([25, 25, 6]) difference() {
    cylinder(d = 20, h = 24);
    translate([0, 0, -1]) cylinder(d = 15, h = 26);
  }
}
