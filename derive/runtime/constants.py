"""Tolerances and settings of the generated solvers (copied into each module that uses them)."""

import math

# the backend of ik and ik_batch calls that name none: "auto" (the arm's C solver where it
# compiles), "c" or "python"
BACKEND = "auto"
CERTIFY_TOL = 1e-6
POSE_TOL = 1e-6
# a pose whose rotation is orthonormal within POSE_TOL but not within this (rounded to float32,
# printed to 8 decimals) is solved for its nearest rotation (_rigid): no joint vector reaches
# a rotation that is not one, and a nominal table's rows, refined within 1e-10 of the pose,
# were refused for every such pose of every such arm (a new user's attack: 100 of 100)
_RIGID_SNAP = 1e-14
DEDUP_TOL = 1e-6
_ROOT_IMAG_TOL = 1e-6
_RESIDUAL_TOL = 1e-8
_MERGE_TOL = 1e-6
# ... two merged roots whose mean leaves the polynomial above this times its largest
# coefficient are two roots, not one split by rounding (the split of a double root by
# coefficients eps * max|p_k| off is about 2 sqrt(eps max|p_k| / |lead|); at four times that,
# p(mean) = lead (gap / 2)^2 is 16 eps max|p_k|): both are kept, not their mean (_accept)
_SPLIT_TOL = 16 * 2.220446049250313e-16
_CLUSTER_TOL = 1e-3
# a cos + b sin = e with |e| up to (1 + _CLAMP_TOL) sqrt(a^2 + b^2) is solved at the boundary:
# earlier joints from a double root (elbow stretched) carry errors of ~1e-8
_CLAMP_TOL = 1e-7
# ... and so is one with |e| up to sqrt(a^2 + b^2) + _CLAMP_ABS sqrt(scale), the equation's own
# size: a small a and b make the ratio sensitive beyond _CLAMP_TOL to an earlier joint's error
# (a Solo12 leg's knee 3e-7 from folded back: its angle from a root 1.5e-7 of 1/u, 7e-5 off
# in the last places of its constant term, and the hip's equation then missed by 3e-11 of its
# scale, 2.3e-4 of its ratio; an OpenArm's elbow 3e-7 from straight: its angle from a root
# 1.5e-7 of 1/u, the shoulder's equation then missed by 1.4e-9 of its scale, 0.9% of its
# ratio, and 13 of 300 such poses got no row); a row from such a miss is certified as any
# other
_CLAMP_ABS = 1e-8
# ... and from |e| down to (1 - _FOLD_TOL) sqrt(a^2 + b^2) as the double root acos(+-1): there
# the angle moves by up to acos(1 - _FOLD_TOL) ~ 1.4e-7 while the equation's residual stays
# below _FOLD_TOL sqrt(a^2 + b^2), and every backend gives the same value (acos near +-1 turns
# one rounding of its argument into 1e-8 of angle)
_FOLD_TOL = 1e-14
_LEAD_TOL = 1e-10
# a step's branch (branch(T, q)) is the sign of its equation's derivative in the joint's value
# at the solution; 0 (a fold: two branches meet, a singular configuration) where the
# derivative is below _BRANCH_FOLD of the equation's scale
_BRANCH_FOLD = 1e-9
_OMEGA = (1.0, complex(-0.5, math.sqrt(3.0) / 2.0), complex(-0.5, -math.sqrt(3.0) / 2.0))
_FREE_TOL = 1e-14  # squared sizes: a joint is free below 1e-7 of its equation's scale
# ... and a two-equation step's (a wrist's theta4 from (W13, W23) = s5 (c4, s4)) on an exact
# table below 1e-10 of its scale (squared: 1e-20): its entries are exact to the arm joints'
# roundings (1e-13 and less; 1e-13 of a singular wrist's s5 gave theta4 from noise, C and
# Python 1e-3 apart), and so is s5 where theta5 comes from atan2(sqrt(W13^2 + W23^2), W33)
# (Cs1Unit), so a wrist 1e-8 from straight has its own theta4 (below 1e-7 it was free, q_ref's:
# a PUMA missed its sampled vector and answered with rows 1e-8 off); likewise a one-equation
# step's (theta1 where the wrist centre is 6e-8 of the reach from axis 1 took q_ref's value, its
# rows 6e-8 off: a new user's attack); a nominal table keeps _FREE_TOL (its arm's difference
# is larger)
_FREE_TOL_EXACT = 1e-20
# ... and in ik's second pass (where the first gave no row: _LOOSE.near) a two-equation step's
# determinant below 1e-4 of its scale (squared: 1e-8) leaves its angle free: an earlier
# joint's error there (a root of a near-double pair, 1e-7 off) made a wrist's s5 3.7e-6
# instead of 0, theta6 came from noise and no row from it (ManiSkill's SO100 URDF, exact, at
# its home pose: a new user's attack); the second pass's rows are polished and certified
_FREE_TOL_LOOSE = 1e-8
# a joint value within this of a limit is inside it: a row on a limit comes back a rounding
# past it (1e-15 from the closed forms, 3e-12 from a quartic's root: KR3's q2 at its limit
# was dropped at 1e-12, a new user's attack); C's DK_LIMIT_SLACK
_LIMIT_SLACK = 1e-9
# the values a free joint tries, as offsets from its preferred value: 0, +5, -5, +10, ... deg
_FREE_STEPS = tuple(math.radians(5.0 * ((k + 1) // 2) * (1 if k % 2 else -1)) for k in range(72))
_TWO_PI = 2.0 * math.pi
# A nominal table's a cos + b sin = e whose a and b nearly cancel (two links of nearly equal
# length folded back) fixes the angle only roughly: within _SPREAD_WIDTH _SEED_TOL sqrt(scale)
# of sqrt(a^2 + b^2) = 0 the arm's difference can move it anywhere, and _SPREAD_COUNT seeds
# all round the circle go to the refinement onto the exact arm
_SPREAD_WIDTH = 0.2
_SPREAD_COUNT = 8
# ... _FOLD_SPREAD of them for one equation's angle (_cs1): near a UR arm's shoulder
# singularity theta1's a and b nearly cancel on the nominal table, and a pair of the exact
# arm's solutions 0.002 rad apart in theta1 was missed (a calibrated UR5 written as a URDF, 7
# of 1,962 regular poses in C with 8; 1 with 16; the calibrated KR6's time unchanged: its
# all-round seeds are the wrist's, which stay _SPREAD_COUNT: 16 made it 22% slower)
_FOLD_SPREAD = 16
# ... and a nominal two-equation step (a wrist's theta6 from s5's terms) whose determinant's
# square root is within _WRIST_WIDTH _SEED_TOL of 0 (the wrist nearly straight: the arm's
# difference over s5 moves the angle anywhere; _SEED_TOL is 100 times the nominal deviation)
# seeds all round too (_SPREAD_COUNT): a calibrated UR5 got no row at q5 = 1.5e-4, and most
# misses near folds of calibrated arms were there. 300 samples near folds (seed 7), vector
# missed by the PUMA, UR5 and KR6: 21, 10, 20 without; 16, 2, 11 with 0.01; 10, 1, 5 with
# 0.03; 5, 1, 3 with 0.2. The seeds that do not converge cost: KR6's C ik 9.6 us on uniform
# poses, 12.7 with 0.01, 14.8 with 0.03, 33.7 with 0.2
_WRIST_WIDTH = 0.03
# ... and beyond that, where the table's difference over the square root (_WRIST_SPREAD
# _SEED_TOL / sqrt(|det| / scale): the angle's uncertainty u, _SEED_TOL being 100 times the
# difference) is at least _WRIST_NEAR radians, t +- u and t +- 2 u seed the refinement too: a
# UR3e zoo URDF (difference 2e-7) 1e-6 rad from its wrist straight got theta6 0.15 rad off,
# the elbow's acos beyond 1 and no row (a new user's attack)
_WRIST_SPREAD = 0.01
_WRIST_NEAR = 0.05
# a look-at row whose ray passes the point within this many radians (or ik's tol, if larger)
# but not within tol * REACH is polished on the exact chain, and kept where that certifies it
# (_aims_at): a point a km away from a head whose axes are 3 mm apart got angles 5e-6 rad
# off (d3's quartic near a double root, then r - d3^2 cancelling) and no row (a new user's
# attack on the GR3 URDF: 100 points per distance, empty 6, 22, 89 at 100 m, 300 m, 1 km;
# 0, 0, 0 with 1e-2, 0, 1, 7 with 1e-4)
_AIM_POLISH = 1e-2
# ... and where its acos argument is beyond _FOLD_NEAR (cos 1e-3: its two values within 1e-3
# of their fold, or one clamped value, where the exact arm's pair may lie up to acos(1 -
# _SEED_MISS) apart), the fold's angle +- each of _FOLD_SEEDS seeds the refinement too: two
# equal seeds refine onto one of the pair and lose the other (a new user's SO-101 MJCF lost
# the elbow's second row 0.03-0.12 rad from its fold), and Newton's steps from either side of
# a fold go to that side's solution; values farther apart already seed either side. A
# polynomial's near-double root (a complex pair within sqrt(_SEED_TOL)) seeds its real part's
# angle +- _FOLD_SEEDS[0] too (a calibrated PUMA's elbow near stretched) (with
# cos 0.01 the seeds came at 13% of a calibrated UR5's poses, and cost 20% of its time; one
# offset of 0.03 finds what 0.01 and 0.1 found on the SO-101, at half the cost)
_FOLD_NEAR = 0.9999995
_FOLD_SEEDS = (0.03,)
# ... or beyond 1 - _FOLD_WIDTH _SEED_TOL (three times the arm's difference), where that is
# lower: a calibration moves a nominal fold's pair more than 1e-3 apart. A calibrated UR5
# URDF (deviation 4.8e-4) near its shoulder's double root had theta1's nominal values 1.2e-3
# from the fold and the exact pair 0.025 either side of it: both values refined onto one of
# the pair, and the sampled vector was missed at 14 (C) and 15 (Python) of 1,960 regular
# poses within 2 mm of the double root, 0 and 0 with this (_cs1)
_FOLD_WIDTH = 0.03
# ... and its acos argument up to _SEED_TOL / up beyond 1 (at least _SEED_TOL, at most
# _SEED_BAND) still seeds the refinement, at the boundary, up being the least condition of
# the angles solved before it (scalar.py _seed_miss): a step before it near a singular
# configuration amplifies the arm's difference (measured: the SO-ARM100 from its MJCF,
# deviation 4.2e-6, its virtual wrist 0.2 deg from straight, condition 0.0035, put the law of
# cosines 2.1% beyond 1 at a pose the arm reaches). _SEED_BAND for every step seeded poses
# the arm does not reach as well, whose seeds never converge: ManiSkill's SO100 URDF spent
# 12% of its C time on them at regular poses, and no row came from them
_SEED_BAND = 0.05
# a refined row within _CURVE_NEAR of an earlier one (radians; lengths over REACH) whose
# midpoint reproduces the pose as well as they do (within _CURVE_FLAT times the smaller of
# their errors, or _CURVE_FLOOR) is that row: both lie on one curve of solutions, a singular
# configuration the exact arm keeps, where each seed converges to a point of its own (Alicia-M
# URDF, its wrist exactly straight: 14 of the 16 rows one configuration, q4 = q6 within 6e-5
# of 0, their midpoints within 3e-14 of the pose, and the other branches left no room; a new
# user's find). Two solutions close together that are not one curve's (a pair at a fold)
# differ at their midpoint by about the square of half their distance: the xArm6 URDF's pairs
# 7e-6 and 7e-5 apart, rows within 2e-15, 5e-13 and 8e-11 there. The smaller error, not the
# larger: a row that stalled at 5e-11 beside a fold took both of its pair (both within 3e-15,
# 1e-4 apart) as points of its curve, in C only (a reviewer's attack on a hextilt URDF)
_CURVE_NEAR = 1e-3
_CURVE_FLAT = 4.0
# a refined row within _STALL_NEAR of another that is a point where its refinement stalled
# beside it, on a valley of points within the row limit that a pose nearly singular makes, is
# that row (refine.py, _stalled_beside: the midpoint of the two refined lands within
# _CURVE_BEND times their distance of the other)
_STALL_NEAR = 0.05
_CURVE_BEND = 0.25
# ... whose errors count as at least this (a few roundings of the pose's entries)
_CURVE_FLOOR = 2.5e-15
# The seam: rounding puts a joint at pi on either side of it, and one solution would get two
# values a full turn apart. A revolute value within _SEAM_BAND above -pi is returned as its
# equivalent just above pi (the value is kept; only the turn changes), and one within
# _SEAM_SNAP of pi as pi itself, in every backend: returned values lie in
# (-pi + _SEAM_BAND, pi + _SEAM_BAND].
_SEAM_BAND = 1e-9
_SEAM_SNAP = 1e-12
_SEAM = math.pi - _SEAM_BAND
# all_turns=True returns at most this many rows (every 2 pi variant of every joint)
MAX_TURN_ROWS = 100_000
# arms with free joints: nearest steps them by FREE_STEP (radians, or length) outward from
# q_ref's values, solving NEAREST_BATCH values at a time; ik_sweep and nearest take at most
# MAX_FREE_VALUES values
FREE_STEP = 0.01
NEAREST_BATCH = 16
MAX_FREE_VALUES = 100_000
# a free joint's value is taken modulo 2 pi (revolute) before it is solved with: at most
# FREE_LIMIT radians (or FREE_LIMIT * REACH of length), where that reduction, and the cos
# and sin of the value, are accurate to ~1e-10
FREE_LIMIT = 1e6
# a pose farther than FAR_REACH * REACH from the base along an axis is out of reach: revolute
# joints reach REACH, no sliding joint a million times that, and the solvers' squares and
# products of such positions would overflow
FAR_REACH = 1e6
# the general 6R method (derive/runtime/general.py): Q's rank counts singular values above
# _RR_RANK_TOL of the largest; a Moebius map x3 = (a y + b) / (c y + d) is kept once the
# leading matrix's condition number is below _RR_COND_LIMIT (else the best of the three; the
# Python solver takes the first map without an SVD where its 1-norm condition number, from
# the inverse it needs anyway, is below _RR_COND_LIMIT / 12: then the 2-norm one is below);
# an eigenvalue is real when |Im| <= _RR_IMAG_TOL (1 + |y|), and real ones closer than
# _RR_CLUSTER_TOL (1 + |y|) are one cluster (the answer is then in doubt); a second singular
# value below _RR_NULL2_TOL of the largest makes the null space two-dimensional (the compiled
# and C solvers compare pivots of an elimination with complete pivoting instead); a candidate
# is kept when _RR_NEWTON_STEPS Newton steps (each at most 0.5 rad per joint, started where
# the pose error is below _RR_NEWTON_REACH), or as many Levenberg-Marquardt steps after them
# (damping |error|^2), bring its pose error below _RR_GOOD (lengths in units of the arm's
# size); the rescue solves the pose moved by each (angle, shift) of _RR_RESCUE and polishes
# back
_RR_RANK_TOL = 1e-10
_RR_COND_LIMIT = 1e8
_RR_MOEBIUS = ((1.0, 0.3, -0.4, 1.0), (1.0, -0.7, 0.5, 1.0), (0.6, 1.0, -1.0, 0.8))
# the null vector's variables are x4 = tan((theta4 - _RR_SHIFT45[0]) / 2) and x5 likewise:
# half-angles of generic shifts, so that the angles where x is infinite (shift + pi) are not
# the special values joints and offsets take (with no shift, theta4 or theta5 = pi at 0 or 180
# degree samples put the solution at x = infinity and the first split lost it)
_RR_SHIFT45 = (0.37, -0.61)
# a complex pair whose theta3 is within _RR_PAIR_ANGLE (radians) of real is also tried, at
# its real part -+ its imaginary part (two near real roots that rounding, or a perturbed
# table's difference, split apart: on xArm6's perturbed table such pairs of the arm's
# solutions lay 0.007-0.113 rad off real, 10 of 10,000 random poses); a sliding joint 3's
# (x3 = d3) within _RR_PAIR_TOL (1 + |y|)
_RR_PAIR_ANGLE = 0.15
_RR_PAIR_TOL = 0.05
_RR_IMAG_TOL = 1e-6
# where nothing certifies otherwise (the pose's pencil is singular: a curve of solutions), the
# eigenvalues with |Im| <= _RR_IMAG_LOOSE (1 + |y|) are tried too
_RR_IMAG_LOOSE = 1e-3
_RR_CLUSTER_TOL = 1e-6
_RR_NULL2_TOL = 1e-5
_RR_GOOD = 1e-10
# where no candidate polishes to _RR_GOOD (a singular pose: the steps converge slowly at an
# isolated multiple solution), those within _RR_NEAR are returned for certification
_RR_NEAR = 1e-7
_RR_NEWTON_STEPS = 10
_RR_NEWTON_REACH = 0.5
# a Newton step from a pose error within _RR_NEWTON_DONE[0], no joint moving more than
# _RR_NEWTON_DONE[1], is the last (its result is not measured: the error after it is at most
# the step squared times the arm's curvature; near a singular Jacobian the step is long); a
# candidate they leave between _RR_NEWTON_DONE[0] and _RR_GOOD (converging slowly, near a
# double root) gets as many again
_RR_NEWTON_DONE = (1e-11, 1e-8)
# a candidate that Newton's steps leave beyond _RR_DAMPED_FROM of the pose takes no damped
# steps (it stays unsettled, as if it had), but on a nominal table (the damped steps bring near
# misses within _SEED_TOL: _rr_fold_seeds) and on an arm with a spherical wrist at an end
# (_RR_FLIPS): there two solutions share the eigen-joint's value, a perturbed table's
# candidate of one can stop between them, and the damped steps from far find the other (the
# PUMA solved by the general method lost solutions at 2 of 440 solves without them, with
# 1e-2 or 0.1). Elsewhere each solution has a candidate of its own, and Newton's steps bring
# one near a solution, a singular one too, within 1e-2; from beyond it the damped steps went
# downhill onto a row another candidate gave. Measured on the five cobots of issue 39: the
# same rows at 5,000 uniform poses (C and Python); at 3,000 special-value poses (C) 12 rows
# lost and 10 gained, each lost one within 3e-7 to 3.3e-5 of a row kept (singular rows,
# sigma_min 1e-8 to 1e-7), where one rounding's move of the poses changed 283 of the
# Jaco2's and the CRX-10iA/L's rows alone; their Python ik 0.84-0.93x (the CRB 15000's 1.0x)
_RR_DAMPED_FROM = 1e-2
# a perturbed table's candidates are polished on tables these shares of the way back first,
# _RR_PATH_STEPS Newton steps on each (a continuation's corrector: it follows the solution,
# the true table's steps settle it; with one, ABB's GoFa 12 lost the pair of a near fold at
# regular poses that two find)
_RR_PATH = (0.3, 0.1, 0.03)
_RR_PATH_STEPS = 2
# a candidate of a later split or pass within _RR_SAME (radians, each joint) of a row found
# before is that row again, and is not polished (on two cobots' perturbed tables: 96% of the
# fallback split's candidates polished onto a row found; a new row was at least 0.02 from
# every earlier one)
_RR_SAME = 1e-2
# a polished candidate within _RR_SAME of a row found, but not within the dedup's 1e-7, whose
# pose error is above this (not settled to rounding) takes two more Newton steps before it is
# compared: near a fold a candidate 1e-12 from the pose can lie 1e-6 from the solution (a G1
# arm's pair 1e-4 apart, found again by the rescue's moved poses: C returned 10 rows to
# Python's 8, a new user's attack)
_RR_SETTLED = 1e-13
# where a perturbed table answered and a row found is within _RR_NEAR_SINGULAR of a singular
# configuration (Hadamard's ratio of its Jacobian: |det J| over the product of its column
# norms), the rescue is tried too: there solutions meet, and the perturbed table's
# continuation may take two onto one
_RR_NEAR_SINGULAR = 1e-3
# a perturbed table's clusters ask for the fallback split (above) unless the split's rows
# already number its real eigenvalues and no complex one lies within _RR_PAIR_DOUBT (1 + |y|)
# of the real line: every real root then gave its row, and no pair of the arm's solutions was
# made complex by the table's difference. On a Jaco2 and a CRX-like arm (3,000 poses each, a
# fifth of the joints at 0, +-90 or 180 deg, moved 1e-3 or 1e-2 rad): the fallback split ran
# at 20% of the poses instead of 90%, and every pose kept its rows; without the second
# condition, two poses (sigma_min 1e-4) lost 4 of their 8. A pair within it asks for the
# fallback split without clusters too (_rr_split: the CRB 15000's C ik 8% slower by the mean,
# the other cobots' within 3%)
_RR_PAIR_DOUBT = 0.03
_RR_RESCUE = ((1e-4, 1e-4), (-2e-4, 1.5e-4))
# on a nominal table (an arm whose exact chain is refined from it: _SEED_TOL > 0), a
# candidate that Newton's and damped steps leave within _SEED_TOL of the pose is a pair of
# the exact arm's solutions near a fold that the nominal table has as a complex pair (or a
# real pair its rounding lost): it seeds the refinement, with the points _RR_FOLD_STEP
# (radians, each way) along the direction the table's Jacobian nearly loses, where the two
# solutions lie (measured on the xArm6 URDF: both found from +-1e-3 at pairs 1e-4 to 1e-2
# apart)
_RR_FOLD_STEP = 1e-3
# two candidates of a nearly real pair that polish onto one row whose Jacobian's least singular
# value is within this (lengths in units of _RR_LENGTH) lost its partner across the fold
# (_rr_fold_partners); elsewhere the pair is complex and its real parts' row is alone (the
# partners' Newton steps there cost the cobots 5-14% of their C time)
_RR_FOLD_NEAR = 1e-2
# where nothing polishes and a pencil on the arm's own table is singular at the pose (or at a
# moved one), or a candidate's polishing stopped within _RR_SEARCH_FROM of it (a curve of
# solutions the eigenvalues missed), _RR_SEARCH_STEPS damped steps from those candidates and
# from 64 fixed starting points (a sliding joint's within +-_RR_SEARCH_SLIDE of the arm's
# size) look for it; it ends after a quarter of them where no row came within _RR_SEARCH_BAIL
_RR_SEARCH_FROM = 0.1
_RR_SEARCH_BAIL = 0.3
# ... "singular at the pose": where nothing polishes and nothing came near, a pencil on the
# arm's own table whose leading matrix under each Moebius map (the pencil at three values of
# x3) has its least singular value (C: its completely pivoted LU factor's least pivot) within
# this of its largest: det vanishing identically in x3, theta3 free along a curve of
# solutions, the eigenvalues the roundings' (a Panda's joints 3-7 with joints 6, 7 at 90 and
# 0 deg, its direction task: 1.6e-14 to 3.1e-14 at all three on pybullet's URDF, 1.8e-16 or
# less on example-robot-data's, and no row)
_RR_SINGULAR = 1e-12
_RR_SEARCH_STEPS = 40
_RR_SEARCH_SLIDE = 1.5
