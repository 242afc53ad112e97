// A 50 x 40 x 20 box whose four vertical edges are rounded (r 6), with a shallow
// spherical dimple in the middle of its top face: a cap of a sphere of radius 20, 3 mm
// deep (its bottom, the sphere polygon's flat pole, at z = 17), centred at x = 25,
// y = 20 (mm). Regenerate with ./make-parts.
$fn = 48;
r = 20;
// OpenSCAD's sphere has no vertex at its pole: its lowest ring is a flat 48-gon at
// r * cos(180 / 48) below the centre. Put that ring at z = 17.
difference() {
  linear_extrude(height = 20) offset(r = 6) offset(delta = -6) square([50, 40]);
  translate([25, 20, 17 + r * cos(180 / 48)]) sphere(r = r);
}
