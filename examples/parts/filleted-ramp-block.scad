// A 70 x 40 x 8 plate carrying three faces that a Z-level zigzag cannot finish:
//  - a round boss, radius 6, 7 mm tall (z 8 to 15), its axis at x = 12, y = 12;
//  - a ramp falling 20 degrees along +X from a vertical end at x = 50 (z 15.28 there) to
//    the plate's edge at x = 70, y from 0 to 20;
//  - a wall along the back (y 32 to 40, up to z = 20) with a concave fillet of radius 5
//    at its foot: its axis along X at y = 27, z = 13 (the fillet spans y 27 to 32).
// The gaps between them take the machine's cutters (32 mm from the boss to the ramp, 7 mm
// from the ramp's side to the fillet), and the walls stand lower than a 3 mm cutter's 8
// mm flutes. The ramp ends in convex edges: where a slope meets a floor in a sharp inside
// edge, a 6 mm ball leaves 0.046 mm in it however fine its rows. Regenerate with
// ./make-parts.
$fn = 96;
union() {
  cube([70, 40, 8]);
  translate([12, 12, 8]) cylinder(r = 6, h = 7);
  // The ramp: a wedge in the XZ plane, extruded along Y.
  translate([0, 20, 0]) rotate([90, 0, 0]) linear_extrude(height = 20)
    polygon([[50, 8], [70, 8], [50, 8 + 20 * tan(20)]]);
  translate([0, 32, 8]) cube([70, 8, 12]);
  // The fillet: the 5 x 5 corner block less a cylinder whose axis is at y = 27, z = 13.
  difference() {
    translate([0, 27, 8]) cube([70, 5, 5]);
    translate([-1, 27, 13]) rotate([0, 90, 0]) cylinder(r = 5, h = 72);
  }
}
