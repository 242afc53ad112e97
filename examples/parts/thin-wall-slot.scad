// Block with a 1.5 mm thin wall between two pockets and a 2.5 mm narrow slot (mm).
// Regenerate with ./make-parts.
block = [60, 40, 30];

difference() {
  cube(block);
  // Two pockets 20 deep leave a wall x = 28 .. 29.5 standing between them.
  translate([8, 5, 10]) cube([20, 30, 21]);
  translate([29.5, 5, 10]) cube([20, 30, 21]);
  // A narrow slot 2.5 wide, 12 deep, across the block.
  translate([52.5, -1, 18]) cube([2.5, 42, 13]);
}
