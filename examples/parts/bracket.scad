// L-bracket with a pocket, holes and fillets (mm). Regenerate with ./make-parts.
$fn = 48;

base = [80, 40, 10];       // plate on the XY plane
upright = [10, 40, 50];    // wall at x = 0..10
fillet = 6;                // inside corner between plate and wall
edge_round = 5;            // outer vertical edges of the plate at x = 80

difference() {
  union() {
    // Plate with its far vertical edges rounded.
    linear_extrude(height = base[2])
      offset(r = edge_round) offset(delta = -edge_round) square([base[0], base[1]]);
    cube(upright);
    // Inside fillet along Y.
    difference() {
      translate([upright[0], 0, base[2]]) cube([fillet, base[1], fillet]);
      translate([upright[0] + fillet, -1, base[2] + fillet]) rotate([-90, 0, 0]) cylinder(r = fillet, h = base[1] + 2);
    }
  }
  // Two vertical through holes in the plate.
  for (y = [10, 30]) translate([68, y, -1]) cylinder(d = 8, h = base[2] + 2);
  // One horizontal through hole in the wall.
  translate([-1, 20, 35]) rotate([0, 90, 0]) cylinder(d = 10, h = upright[0] + 2);
  // Pocket on top of the plate, corner radius 3, 4 deep.
  translate([28, 12, base[2] - 4]) linear_extrude(height = 5)
    offset(r = 3) offset(delta = -3) square([24, 16]);
}
