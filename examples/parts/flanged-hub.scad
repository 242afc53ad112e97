// A hub 20 mm across and 30 tall with a 50 mm flange, 5 thick, at its top: the flange
// overhangs the hub by 15 mm all round (mm). Regenerate with ./make-parts.
$fn = 48;
translate([25, 25, 0]) union() {
  cylinder(d = 20, h = 30);
  translate([0, 0, 30]) cylinder(d = 50, h = 5);
}
