// A 50 x 30 x 24 block with a closed square channel inside under a 4 mm lid: 8 x 8,
// along X from x = 5 to x = 45, y = 11..19, z = 12..20; its roof is 4 mm under the top
// face and it does not open to the outside (mm). Regenerate with ./make-parts.
difference() {
  cube([50, 30, 24]);
  translate([5, 11, 12]) cube([40, 8, 8]);
}
