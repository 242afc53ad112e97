// A 60 x 40 x 30 block with a closed round channel inside: 8 mm across, along X from
// x = 6 to x = 54 at y = 20, z = 15; no opening to the outside (mm).
// Regenerate with ./make-parts.
$fn = 48;
difference() {
  cube([60, 40, 30]);
  translate([6, 20, 15]) rotate([0, 90, 0]) cylinder(d = 8, h = 48);
}
