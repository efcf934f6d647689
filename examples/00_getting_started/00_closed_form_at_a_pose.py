"""The closed form at one pose

The paper's prototype (Tables 1-2) at one platform position `p`: the actuator positions of the inverse kinematics
(eq. 4), both assembly modes of the forward kinematics back from them (eqs. 1, 27), the Jacobians and the two
singularity measures (eqs. 7-12), the status the app shows, the actuator forces that hold a load at rest (eq. 13 with
the load's sign) and the forces of a motion through that pose (eqs. 29-31). SI units throughout: m, m/s, m/s², N.
"""

import numpy as np

import tpm_viz as tv

params = tv.Params.paper()  # a = 482 mm, b = 92 mm, l_a = 260 mm, stroke 300 mm, the paper's masses
p = np.array([0.05, -0.02])  # platform position [m]

d = tv.inverse_kinematics(params, p)  # eq. (4), the working mode
print(f"p = {p * 1e3} mm  ->  d = {np.round(d * 1e3, 3)} mm")

both = tv.forward_kinematics_both(params, d)  # the two intersections of the leg circles
print(f"forward kinematics: P = {np.round(both.plus * 1e3, 3)} mm, P' = {np.round(both.minus * 1e3, 3)} mm")
assert np.allclose(both.plus, p) or np.allclose(both.minus, p)  # one of them is where we started

jac = tv.jacobians(params, p)  # jx, jq (eq. 8), j (eq. 10), det_jx and det_jq (eqs. 11-12)
theta = tv.leg_angles(params, p)  # θ1, θ2 [rad]
assert np.allclose(jac.j, [[1, np.tan(theta[0])], [np.tan(theta[1]), 1]])  # J = [[1, tan θ1], [tan θ2, 1]]
print(f"J = {np.round(jac.j, 4).tolist()}, det J_x = {float(jac.det_jx):.4f}, det J_q = {float(jac.det_jq):.4f}")
print(f"condition number of J: {float(tv.condition_number(params, p)):.3f}")
print(f"status: {tv.PoseStatus(int(tv.classify(params, p))).name}")  # REGULAR, NEAR_INVERSE, NEAR_DIRECT, ...

load = np.array([0.0, 5.0])  # an external force on the platform [N]
hold = tv.actuator_forces_from_platform_force(params, p, -load)  # eq. (13): f = J^T tau, with f = -f_ext
print(f"to hold {load} N at rest: tau = {np.round(hold, 3)} N")
tau_static = tv.inverse_dynamics(params, p, [0.0, 0.0], [0.0, 0.0], f_ext=load)
assert np.allclose(tau_static, hold)  # the dynamics at rest is the statics

tau = tv.inverse_dynamics(params, p, dp=[0.5, -0.2], ddp=[4.0, 1.0])  # eqs. (29)-(31)
print(f"moving through p at (0.5, -0.2) m/s, accelerating at (4, 1) m/s^2: tau = {np.round(tau, 3)} N")
