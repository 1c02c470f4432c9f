"""URDFs for the singular-loci tests (issue 44), written from their dimensions: a five-bar with unequal
distal links and a planar 3-RPR of the design of Innocenti & Parenti-Castelli (1998), studied by Zein,
Wenger & Chablat (2008) (base A1 (0, 0), A2 (15.91, 0), A3 (0, 10); platform sides B1B2 17.04, B2B3 16.54,
B1B3 20.84; here in hundredths: metres)."""

import numpy as np

_LINK = ('<link name="{n}"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" '
         'ixz="0" iyz="0"/></inertial></link>')


def _joint(name, kind, parent, child, xyz, axis="0 0 1", lower=-100, upper=100):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{float(xyz[0])!r} {float(xyz[1])!r} 0" rpy="0 0 0"/><axis xyz="{axis}"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/></joint>')


def _actuated(*names):
    return "".join(f'<transmission name="t_{n}"><type>transmission_interface/SimpleTransmission</type>'
                   f'<joint name="{n}"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>'
                   f'<actuator name="m_{n}"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>'
                   for n in names)


def _loop(name, l1, p1, l2, p2):
    return (f'<loop_joint name="{name}" type="revolute"><link1 link="{l1}" xyz="{float(p1[0])!r} {float(p1[1])!r} 0" rpy="0 0 0"/>'
            f'<link2 link="{l2}" xyz="{float(p2[0])!r} {float(p2[1])!r} 0" rpy="0 0 0"/><axis xyz="0 0 1"/></loop_joint>')


#: five-bar: ground pivots (0, 0), (D, 0); proximal links A1, A2; distal B1, B2; drawn with the motors at HOME
FIVE_BAR = {"D": 0.1, "a1": 0.1, "a2": 0.1, "b1": 0.15, "b2": 0.12, "home": (np.radians(120), np.radians(60))}


def five_bar(D, a1, a2, b1, b2, home):
    """(URDF text, function (motor1, motor2) -> (A1, A2, B1, B2) in the plane).  A motor's joint value is
    its proximal link's angle minus the drawn one."""
    A1, A2 = np.zeros(2), np.array([D, 0.0])
    u = lambda t: np.array([np.cos(t), np.sin(t)])
    B1, B2 = A1 + a1 * u(home[0]), A2 + a2 * u(home[1])
    d = np.linalg.norm(B2 - B1)
    e = (B2 - B1) / d
    m = (b1**2 - b2**2 + d**2) / (2 * d)
    P = B1 + m * e + np.sqrt(b1**2 - m**2) * np.array([-e[1], e[0]])
    body = "".join(_LINK.format(n=n) for n in ("ground", "proximal1", "distal1", "proximal2", "distal2"))
    body += '<link name="tip"/>'
    body += _joint("motor1", "revolute", "ground", "proximal1", A1)
    body += _joint("elbow1", "revolute", "proximal1", "distal1", B1 - A1)
    body += _joint("motor2", "revolute", "ground", "proximal2", A2)
    body += _joint("elbow2", "revolute", "proximal2", "distal2", B2 - A2)
    body += f'<joint name="tip_joint" type="fixed"><parent link="distal1"/><child link="tip"/>' \
            f'<origin xyz="{float((P - B1)[0])!r} {float((P - B1)[1])!r} 0"/></joint>'
    body += _loop("end_joint", "distal1", P - B1, "distal2", P - B2)
    text = f'<?xml version="1.0"?><robot name="five_bar_loci">{body}{_actuated("motor1", "motor2")}</robot>'

    def elbows(m1, m2):
        return A1, A2, A1 + a1 * u(home[0] + m1), A2 + a2 * u(home[1] + m2)

    return text, elbows


#: 3-RPR (Innocenti & Parenti-Castelli 1998), lengths in metres (the published values / 100)
RPR_BASE = np.array([[0.0, 0.0], [0.1591, 0.0], [0.0, 0.10]])
_d12, _d23, _d13 = 0.1704, 0.1654, 0.2084
_bx = (_d13**2 - _d23**2 + _d12**2) / (2 * _d12)
RPR_PLATFORM = np.array([[0.0, 0.0], [_d12, 0.0], [_bx, np.sqrt(_d13**2 - _bx**2)]])  # B_i in the platform's frame
RPR_HOME = (np.array([0.05, 0.06]), np.radians(30.0))  # B1's position and the platform's angle, drawn


def rpr3(base=RPR_BASE, platform=RPR_PLATFORM, home=RPR_HOME):
    """(URDF text, the home leg lengths rho0 (3,)): a leg's joint value is its length minus rho0.  Another
    3-RPR: its ``base`` and ``platform`` points (3, 2) and ``home`` (B1's position, the platform's angle)."""
    base, platform = np.asarray(base, float), np.asarray(platform, float)
    c, s = np.cos(home[1]), np.sin(home[1])
    R = np.array([[c, -s], [s, c]])
    B = home[0] + platform @ R.T
    rho0 = np.linalg.norm(B - base, axis=1)
    names = ["ground", "platform"] + [f"{k}{i}" for i in (1, 2, 3) for k in ("cylinder", "piston")]
    body = "".join(_LINK.format(n=n) for n in names)
    for i in range(3):
        u = (B[i] - base[i]) / rho0[i]
        body += _joint(f"base{i + 1}", "revolute", "ground", f"cylinder{i + 1}", base[i])
        body += _joint(f"leg{i + 1}", "prismatic", f"cylinder{i + 1}", f"piston{i + 1}", (0.0, 0.0),
                       axis=f"{float(u[0])!r} {float(u[1])!r} 0", lower=-0.3, upper=0.3)
    body += _joint("wrist1", "revolute", "piston1", "platform", B[0] - base[0])
    # the platform's frame at B1, turned like the ground's at home: B_i - B1 in it are R (B_i - B1 in the drawing)
    for i in (1, 2):
        body += _loop(f"wrist{i + 1}", f"piston{i + 1}", B[i] - base[i], "platform", B[i] - B[0])
    text = f'<?xml version="1.0"?><robot name="rpr3_innocenti">{body}{_actuated("leg1", "leg2", "leg3")}</robot>'
    return text, rho0


def rpr3_polynomial(rho):
    """The 3-RPR's forward-kinematics polynomial in t = tan(phi / 2) (phi: the platform's turn from its frame
    in RPR_PLATFORM), built here with numpy's polynomials, independent of screwkin: the two leg equations
    less the first are linear in B1; B1 put into the first gives a polynomial of degree 8 in t whose real
    roots are the assembly modes (the factor 1 + t^2 aside)."""
    from numpy.polynomial import Polynomial as P
    one, c, s = P([1, 0, 1]), P([1, 0, -1]), P([0, 2])  # (1 + t^2) x {1, cos phi, sin phi}
    A, b = RPR_BASE, RPR_PLATFORM
    rows, rhs = [], []
    for i in (1, 2):  # |B1 + R b_i - A_i|^2 - |B1 - A1|^2 = rho_i^2 - rho_1^2, linear in B1
        w = [b[i][0] * c - b[i][1] * s - A[i][0] * one, b[i][0] * s + b[i][1] * c - A[i][1] * one]  # (R b_i - A_i)
        rows.append([2 * (w[0] + A[0][0] * one), 2 * (w[1] + A[0][1] * one)])
        # |R b_i - A_i|^2 = |b_i|^2 + |A_i|^2 - 2 A_i . R b_i: degree 1 in (c, s)
        Rb = [b[i][0] * c - b[i][1] * s, b[i][0] * s + b[i][1] * c]
        w2 = (b[i] @ b[i] + A[i] @ A[i]) * one - 2 * (A[i][0] * Rb[0] + A[i][1] * Rb[1])
        rhs.append((rho[i] ** 2 - rho[0] ** 2 + A[0] @ A[0]) * one - w2)
    det = rows[0][0] * rows[1][1] - rows[0][1] * rows[1][0]  # degree 2
    N = [rows[1][1] * rhs[0] - rows[0][1] * rhs[1], rows[0][0] * rhs[1] - rows[1][0] * rhs[0]]  # B1 det, degree 2
    return (N[0] ** 2 + N[1] ** 2 - 2 * (A[0][0] * N[0] + A[0][1] * N[1]) * det
            + (A[0] @ A[0] - rho[0] ** 2) * det ** 2)


def root_cluster(poly, k):
    """The tightest cluster of k roots of poly: (their largest pairwise distance, their mean)."""
    from itertools import combinations
    r = poly.roots()
    best = min(combinations(r, k), key=lambda g: max(abs(a - b) for a, b in combinations(g, 2)))
    return max(abs(a - b) for a, b in combinations(best, 2)), complex(np.mean(best))


def rpr3_cusp(rho1, rho2, rho3, t):
    """The cusp of the polynomial's section rho1 = const nearest (rho2, rho3) and the root t: Newton on
    P = P' = P'' = 0 in (t, rho2, rho3) (the coefficients normalised; derivatives in rho by central
    differences).  Returns (rho2, rho3, t)."""
    z = np.array([t, rho2, rho3], float)

    def G(z):
        P = rpr3_polynomial((rho1, z[1], z[2]))
        P = P / np.linalg.norm(P.coef)
        return np.array([P(z[0]), P.deriv(1)(z[0]), P.deriv(2)(z[0])])

    for _ in range(30):
        g = G(z)
        J = np.empty((3, 3))
        for k in range(3):
            h = np.zeros(3)
            h[k] = 1e-6
            J[:, k] = (G(z + h) - G(z - h)) / 2e-6
        dz = np.linalg.solve(J, -g)
        z = z + dz
        if np.abs(dz).max() < 1e-15:
            break
    return z[1], z[2], z[0]


def orthogonal_3r(d2, d3, d4, r2, r3):
    """An orthogonal 3R in the modified Denavit-Hartenberg parameters of Baili, Wenger & Chablat (2004):
    alpha = (0, -90, 90) deg, a = (0, d2, d3), r = (0, r2, r3), the tool point at d4 along x3; its output
    link is `tool`."""
    links = "".join(_LINK.format(n=n) for n in ("base", "link1", "link2", "link3")) + '<link name="tool"/>'

    def joint(name, parent, child, xyz, roll):
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{float(xyz[0])!r} {float(xyz[1])!r} {float(xyz[2])!r}" rpy="{float(roll)!r} 0 0"/>'
                '<axis xyz="0 0 1"/><limit lower="-3.1416" upper="3.1416" effort="1" velocity="1"/></joint>')

    body = links + joint("theta1", "base", "link1", (0, 0, 0), 0.0)
    body += joint("theta2", "link1", "link2", (d2, 0, 0), -np.pi / 2)
    body += joint("theta3", "link2", "link3", (d3, 0, r2), np.pi / 2)
    body += f'<joint name="tool_joint" type="fixed"><parent link="link3"/><child link="tool"/>' \
            f'<origin xyz="{float(d4)!r} 0 {float(r3)!r}"/></joint>'
    return f'<?xml version="1.0"?><robot name="orthogonal_3r">{body}</robot>'


def orthogonal_3r_quartic(d2, d3, d4, r2, r3, x, z):
    """The inverse kinematics of orthogonal_3r at the point (x, 0, z), as a polynomial in t = tan(theta3 / 2)
    (numpy, independent of screwkin): with R^2 = x^2 + z^2, the tool point's distance from the base and its
    height give (K - 2 d3 d4 c3 - 2 r2 d4 s3)^2 + 4 d2^2 (z^2 - (d3 + d4 c3)^2 - r3^2) = 0,
    K = R^2 - d2^2 - d3^2 - d4^2 - r2^2 - r3^2; each real root is one solution (theta2 and theta1 follow)."""
    from numpy.polynomial import Polynomial
    return Polynomial(orthogonal_3r_quartic_coefficients(d2, d3, d4, r2, r3, x, z))


def orthogonal_3r_quartic_coefficients(d2, d3, d4, r2, r3, x, z):
    """The coefficients (5, ...) of orthogonal_3r_quartic, lowest first, at points x, z (arrays alike)."""
    x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
    one, c, s = np.array([1.0, 0, 1]), np.array([1.0, 0, -1]), np.array([0.0, 2, 0])
    K = x * x + z * z - d2**2 - d3**2 - d4**2 - r2**2 - r3**2
    first = K[None] * one.reshape(3, *[1] * K.ndim) + (-2 * d3 * d4 * c - 2 * r2 * d4 * s).reshape(3, *[1] * K.ndim)
    ux = d3 * one + d4 * c

    def times(a, b):  # the product of two quadratics in t (coefficients first)
        return np.stack([sum(a[i] * b[k - i] for i in range(3) if 0 <= k - i < 3) for k in range(5)])

    ones = np.broadcast_to(times(one, one).reshape(5, *[1] * K.ndim), (5,) + K.shape)
    return times(first, first) + 4 * d2**2 * ((z * z - r3**2)[None] * ones - times(ux, ux).reshape(5, *[1] * K.ndim))
