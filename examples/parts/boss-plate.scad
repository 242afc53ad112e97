// A plate 100 x 80 x 12 mm with a round boss 40 mm across standing 60 mm tall on its
// middle: the kind of part a shop builds by wire-fed deposition on a plate of the base's
// thickness and then mills to size, instead of milling it all from a 72 mm block.
// Regenerate with ./make-parts.
$fn = 64;
union() {
  cube([100, 80, 12]);
  translate([50, 40, 12]) cylinder(d = 40, h = 60);
}
