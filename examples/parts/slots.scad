// A 60 x 40 x 20 block with three slots along Y, 0.5, 1 and 1.5 mm wide and 10 deep (mm):
// gaps no wider than twice the bundled machines' tolerance. Regenerate with ./make-parts.
block = [60, 40, 20];
difference() {
  cube(block);
  translate([15, -1, 10]) cube([0.5, 42, 11]);
  translate([30, -1, 10]) cube([1, 42, 11]);
  translate([45, -1, 10]) cube([1.5, 42, 11]);
}
