// A 60 x 40 x 40 block with a closed channel inside whose roof builds without support:
// 8 mm wide, straight walls from z = 22 to 26, then a pointed arch whose sides lean 25
// degrees from the vertical up to z = 34.58 (within a 30 degree overhang limit), along X
// from x = 6 to 54, centred at y = 20. A shop mills the block up to the channel's floor
// from stock and deposits only the band from there up (mm).
// Regenerate with ./make-parts.
rise = 4 / tan(25);
difference() {
  cube([60, 40, 40]);
  translate([6, 0, 0]) rotate([90, 0, 90]) linear_extrude(height = 48)
    polygon([[16, 22], [24, 22], [24, 26], [20, 26 + rise], [16, 26]]);
}
