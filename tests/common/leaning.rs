//! A group of leaning blocks (a fallen domino train) as resolver input.
//!
//! Blocks of height h and thickness d stand at pitch λ = s + d, all tilted
//! forward by the rest angle θ∞ (cos θ∞ = d/λ) so that each block's top front
//! corner rests on the back face of the block ahead and its front bottom edge
//! on the ground. The last block is pushed: it turns about its edge with
//! angular velocity `push` (rad/s, clockwise = toppling forward).

use topple::impact::{Body, Contact, ContactMaterial};

pub struct Leaning {
    pub count: usize,
    pub height: f64,
    pub thickness: f64,
    pub spacing: f64,
    pub push: f64,
    pub between: ContactMaterial,
    pub ground: ContactMaterial,
}

impl Leaning {
    pub fn build(&self) -> (Vec<Body>, Vec<Contact>) {
        let (h, d) = (self.height, self.thickness);
        let pitch = self.spacing + d;
        let tilt = (d / pitch).acos(); // clockwise tilt, rad
        let (s, c) = (tilt.sin(), tilt.cos());
        let mass = 1.0;
        let inertia = mass * (h * h + d * d) / 12.0;
        let mut bodies = Vec::new();
        let mut contacts = Vec::new();
        for i in 0..self.count {
            // front bottom edge (pivot) at x = i λ on the ground
            let pivot = [i as f64 * pitch, 0.0];
            // centre: from the pivot, −d/2 along the block's x axis and +h/2
            // along its y axis; axes turned clockwise by `tilt`
            let x_axis = [c, -s];
            let y_axis = [s, c];
            let centre = [
                pivot[0] - 0.5 * d * x_axis[0] + 0.5 * h * y_axis[0],
                pivot[1] - 0.5 * d * x_axis[1] + 0.5 * h * y_axis[1],
            ];
            let mut body = Body::new(mass, inertia).with_position(centre);
            body.angle = -tilt;
            if i == 0 {
                // rotation about the pivot with ω = −push (counter-clockwise
                // positive): v = ω × (centre − pivot)
                let w = -self.push;
                let r = [centre[0] - pivot[0], centre[1] - pivot[1]];
                body = body
                    .with_velocity([-w * r[1], w * r[0]])
                    .with_angular_velocity(w);
            }
            bodies.push(body);
            contacts.push(Contact::new(
                [None, Some(i)],
                pivot,
                [0.0, 1.0],
                self.ground,
            ));
            if i + 1 < self.count {
                // top front corner of block i on the back face of block i+1
                let corner = [pivot[0] + h * y_axis[0], pivot[1] + h * y_axis[1]];
                // back face normal of block i+1 (its −x axis): from i to i+1 is +x axis
                contacts.push(Contact::new(
                    [Some(i), Some(i + 1)],
                    corner,
                    x_axis,
                    self.between,
                ));
            }
        }
        (bodies, contacts)
    }
}
