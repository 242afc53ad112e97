// An angle bracket with gussets (mm): a 70 x 40 x 6 base plate and a 6 mm upright at
// x = 0..6 rising 40 mm above the plate (46 from the bottom), braced by two triangular
// gussets 5 thick (y = 5..10 and 30..35) whose 45 degree faces run from x = 26 on the
// plate up to z = 26 on the upright. Two vertical 6.5 mm bolt holes pass through the
// plate at x = 52, y = 10 and 30, and one horizontal 6.5 mm hole through the upright
// along X at y = 20, z = 36. Regenerate with ./make-parts.
$fn = 48;
difference() {
  union() {
    cube([70, 40, 6]);
    cube([6, 40, 46]);
    // Gussets: right triangles in XZ, legs 20 along the plate and up the upright.
    for (y = [5, 30]) translate([0, y + 5, 0]) rotate([90, 0, 0]) linear_extrude(height = 5)
      polygon([[6, 6], [26, 6], [6, 26]]);
  }
  for (y = [10, 30]) translate([52, y, -1]) cylinder(d = 6.5, h = 8);
  translate([-1, 20, 36]) rotate([0, 90, 0]) cylinder(d = 6.5, h = 8);
}
