// A 60 x 40 x 20 block with a 50 x 30 pocket 12 deep, crossed by three 1 mm ribs along Y
// that stand 10 mm tall in it (mm). Regenerate with ./make-parts.
block = [60, 40, 20];
union() {
  difference() {
    cube(block);
    translate([5, 5, 8]) cube([50, 30, 13]);
  }
  for (x = [17, 29.5, 42]) translate([x, 5, 8]) cube([1, 30, 10]);
}
