// A 40 x 30 x 10 base with a wall 6 thick and 20 long standing on it (x = 10..16 at its
// foot, y = 5..25) that leans out 30 degrees from the vertical towards +X, 15 mm tall
// (z = 10..25). The lean builds without support, and no cutter from above reaches its
// outer face: the deposit must lay that face within tolerance as it is.
// Regenerate with ./make-parts.
union() {
  cube([40, 30, 10]);
  multmatrix([[1, 0, tan(30), 0], [0, 1, 0, 0], [0, 0, 1, 0]]) translate([10, 5, 10]) cube([6, 20, 15]);
}
