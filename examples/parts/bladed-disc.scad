// A bladed disc: a hub 20 mm across with an 8 mm bore, 12 tall, on a base disc 60 mm
// across and 2 thick, carrying six radial blades 2.5 thick and 12 tall (z = 0..12) at
// 60 degrees from one another (0, 60, ..., 300 from +X), out to the disc's rim at 30 mm;
// four of them lie off the grid axes. Centred at x, y = 30 (mm). Regenerate with
// ./make-parts.
$fn = 48;
translate([30, 30, 0]) difference() {
  union() {
    cylinder(r = 30, h = 2);
    cylinder(d = 20, h = 12);
    // The blades, trimmed to the disc's rim.
    intersection() {
      union() for (a = [0 : 60 : 300]) rotate([0, 0, a]) translate([8, -1.25, 0]) cube([23, 2.5, 12]);
      cylinder(r = 30, h = 12);
    }
  }
  translate([0, 0, -1]) cylinder(d = 8, h = 14);
}
