// A 50 x 50 x 8 slab on a 20 x 20 x 30 column: the slab's underside cannot be reached
// from above (+Z). Regenerate with ./make-parts.
union() {
  translate([15, 15, 0]) cube([20, 20, 30]);
  translate([0, 0, 30]) cube([50, 50, 8]);
}
