// A 12 x 12 square post, 20 tall, under a 33 x 33 square cap whose underside is a chamfer
// leaning 60 degrees from the vertical: it hangs 10.5 mm out on every side over 6.06 mm
// of height (z = 20..26.06), and the cap stands straight up to z = 30. Deposited from
// below, the chamfer leans past a powder head's 30 degrees. Regenerate with ./make-parts.
lean = 60;                       // degrees from the vertical
post = 12;                       // mm across
post_height = 20;
cap = 33;                        // mm across
top = 30;
out = (cap - post) / 2;          // 10.5: how far the cap hangs out
chamfer = out / tan(lean);       // 6.06: the chamfer's height
union() {
  translate([out, out, 0]) cube([post, post, post_height]);
  translate([cap / 2, cap / 2, post_height]) linear_extrude(height = chamfer, scale = cap / post) square(post, center = true);
  translate([0, 0, post_height + chamfer]) cube([cap, cap, top - post_height - chamfer]);
}
