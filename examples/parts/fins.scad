// A 60 x 40 x 5 plate with four 1 mm fins, 15 mm tall, along Y (mm): features no thicker
// than twice the bundled machines' tolerance. Regenerate with ./make-parts.
plate = [60, 40, 5];
union() {
  cube(plate);
  for (x = [10, 22, 34, 46]) translate([x, 5, plate[2]]) cube([1, 30, 15]);
}
