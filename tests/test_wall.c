/*
 * test_wall.c: unit test of the plane-wall closed forms of solver/wall.h against quadrature of
 * the Wendland kernel of solver/kernel.h (h = 1, distances in units of h, wall at distance q):
 *  - wall_gamma(dim, q)   = integral of w over the fluid side y > -q    (thesis Eq. 4.10 in 3-D)
 *  - wall_dgamma(dim, q)  = integral of w over the wall plane/line      (thesis Eq. 4.9, 4.11)
 *  - wall_moment2(dim, q) = integral of r w'(r) over the region behind the wall, y > q
 *    (r_ab . grad_a w_ab = F r^2 = r w'(r)); all to 1e-10 relative for q on a grid in (0, 2);
 *  - 2-D: the sum of wall_segment_2d (Ferrand Eq. 51-52) over consecutive segments of length
 *    0.3 and 0.77 with random offsets covering the whole line equals wall_dgamma to 1e-12;
 *  - endpoints gamma(0) = 1/2, gamma(2) = 1, dgamma(2) = 0, moment2(0) = -dim/2, moment2(2) = 0;
 *  - the Wendland C4 forms (3-D): gamma, h |grad gamma|, moment2 and moment_yy (the integral
 *    of F r_y^2 behind the wall) against the same quadrature of the C4 kernel to 1e-10
 *    relative, and the *_of functions pick the forms of the kernel's shape.
 *
 * Quadrature. 3-D: the region y > d meets the sphere of radius r > d in a cap of area
 * 2 pi r (r - d), the plane y = d in a disc, so every integral is radial with a polynomial
 * integrand (Gauss-Legendre exact). 2-D: the circle of radius r > d has an arc of length
 * 2 r acos(d/r) in y > d; the substitution r = d cosh(u) turns acos(d/r) = atan(sinh u) and the
 * line integral (x = d sinh u) into functions analytic on the interval (no sqrt singularity at
 * r = d, no near-singularity at x = +-i d), integrated with composite 20-point Gauss-Legendre;
 * the rule is run with 24 and 48 panels and the two must agree to 1e-13.
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>

#include "kernel.h"
#include "quadrature.h"
#include "wall.h"

enum { GL_N = 20 };

/* Absolute floor of the 2-D comparisons. The 2-D closed forms (and Ferrand's segment formula)
   add terms of size O(1) that cancel to O((2 - q)^4.5) as q -> 2, so in double precision they
   are accurate to ~1e-15 absolute, not relative (at q = 1.98 the relative error is ~1e-7 even
   though the formulas are exact: checked to 30 digits with mpmath). The floor only matters
   where the value is below 1e4 * ATOL_2D (1e-10) or 1e2 * ATOL_2D (1e-12) respectively. */
#define ATOL_2D 1e-14
static double gl_x[GL_N], gl_w[GL_N];

/** Integrand: f(t; q, kernel). */
typedef double (*integrand)(double t, double q, const struct kernel *k);

/** Composite Gauss-Legendre over [a, b] with np equal panels. */
static double integrate(integrand f, double a, double b, int np, double q, const struct kernel *k) {
  const double len = (b - a) / np;
  double s = 0.0;
  for (int p = 0; p < np; p++) {
    const double mid = a + (p + 0.5) * len, half = 0.5 * len;
    double sp = 0.0;
    for (int i = 0; i < GL_N; i++) sp += gl_w[i] * f(mid + half * gl_x[i], q, k);
    s += half * sp;
  }
  return s;
}

/* ---- 3-D integrands (variable r), polynomial in r ---- */
static double w3_ball(double r, double q, const struct kernel *k) {
  (void)q;
  return 4.0 * M_PI * r * r * kernel_w(k, r);
}
/* sphere of radius r > q: area 4 pi r^2 - 2 pi r (r - q) lies on the fluid side y > -q */
static double w3_fluid(double r, double q, const struct kernel *k) {
  return 2.0 * M_PI * r * (r + q) * kernel_w(k, r);
}
/* plane at distance q: disc, rho drho = r dr */
static double w3_plane(double r, double q, const struct kernel *k) {
  (void)q;
  return 2.0 * M_PI * r * kernel_w(k, r);
}
/* r w'(r) = F r^2 over the cap behind the wall */
static double m3_behind(double r, double q, const struct kernel *k) {
  return kernel_f(k, r) * r * r * 2.0 * M_PI * r * (r - q);
}

/* ---- 2-D integrands ---- */
static double w2_disc(double r, double q, const struct kernel *k) {
  (void)q;
  return 2.0 * M_PI * r * kernel_w(k, r);
}
/* behind the wall, r = q cosh u: arc 2 r atan(sinh u), dr = q sinh u du */
static double w2_behind(double u, double q, const struct kernel *k) {
  const double r = q * cosh(u);
  return 2.0 * r * atan(sinh(u)) * kernel_w(k, r) * q * sinh(u);
}
static double m2_behind(double u, double q, const struct kernel *k) {
  const double r = q * cosh(u);
  return 2.0 * r * atan(sinh(u)) * kernel_f(k, r) * r * r * q * sinh(u);
}
/* along the wall line, x = q sinh u, both halves */
static double w2_line(double u, double q, const struct kernel *k) {
  const double r = q * cosh(u);
  return 2.0 * kernel_w(k, r) * r;
}

/** Reference values by quadrature with np panels (np and 2 np are compared). */
static void reference(int dim, double q, int np, double *gam, double *dgam, double *mom) {
  const struct kernel k = kernel_make(dim, 1.0);
  if (dim == 3) {
    /* polynomial integrands: one panel per piece is already exact; np panels are used anyway */
    *gam = integrate(w3_ball, 0.0, q, np, q, &k) + integrate(w3_fluid, q, 2.0, np, q, &k);
    *dgam = integrate(w3_plane, q, 2.0, np, q, &k);
    *mom = integrate(m3_behind, q, 2.0, np, q, &k);
  } else {
    const double umax = acosh(2.0 / q);
    *gam = integrate(w2_disc, 0.0, 2.0, np, q, &k) - integrate(w2_behind, 0.0, umax, np, q, &k);
    *dgam = integrate(w2_line, 0.0, umax, np, q, &k);
    *mom = integrate(m2_behind, 0.0, umax, np, q, &k);
  }
}

static double rel_err(double a, double ref) {
  return fabs(a - ref) / fabs(ref);
}

/* F r_y^2 over the cap behind the wall: int_cap y^2 dA = 2 pi r (r^3 - q^3) / 3 */
static double myy3_behind(double r, double q, const struct kernel *k) {
  return kernel_f(k, r) * 2.0 * M_PI * r * (r * r * r - q * q * q) / 3.0;
}

/** The C4 closed forms of wall.h against quadrature of the C4 kernel (3-D); returns failures. */
static int check_c4(void) {
  const struct kernel k = kernel_make_shape(3, 1.0, KERNEL_C4), k2 = kernel_make(3, 1.0);
  double e_max[4] = {0.0, 0.0, 0.0, 0.0};
  int fail = 0;
  for (int iq = 0; iq <= 100; iq++) {
    const double q = 0.02 * iq;
    const double ref[4] = {
        q > 0.0 ? integrate(w3_ball, 0.0, q, 4, q, &k) + integrate(w3_fluid, q, 2.0, 4, q, &k)
                : integrate(w3_fluid, 0.0, 2.0, 4, q, &k),
        integrate(w3_plane, q, 2.0, 4, q, &k), integrate(m3_behind, q, 2.0, 4, q, &k),
        integrate(myy3_behind, q, 2.0, 4, q, &k)};
    const double val[4] = {wall_gamma_of(&k, q), wall_dgamma_of(&k, q), wall_moment2_of(&k, q),
                           wall_moment_yy_of(&k, q)};
    for (int j = 0; j < 4; j++) {
      const double ea = fabs(val[j] - ref[j]), scale = j == 0 ? 1.0 : fabs(ref[j]);
      if (q < 2.0 && ea / scale > e_max[j]) e_max[j] = ea / scale;
      if (!(ea <= 1e-10 * scale + (q >= 2.0 ? 1e-300 : 0.0))) {
        printf("FAIL: C4 q %.2f: function %d = %.17g, quadrature %.17g\n", q, j, val[j], ref[j]);
        fail = 1;
      }
    }
    /* the dispatch: a C2 kernel still gets the C2 forms */
    if (wall_gamma_of(&k2, q) != wall_gamma(3, q) || wall_dgamma_of(&k2, q) != wall_dgamma(3, q)) {
      printf("FAIL: q %.2f: wall_*_of of a C2 kernel differs from the C2 forms\n", q);
      fail = 1;
    }
  }
  if (!(fabs(wall_gamma_c4(0.0) - 0.5) <= 1e-15 && fabs(wall_moment2_c4(0.0) + 1.5) <= 1e-15 &&
        fabs(wall_moment_yy_c4(0.0) + 0.5) <= 1e-15)) {
    printf("FAIL: C4 endpoints gamma(0) %.17g, moment2(0) %.17g, moment_yy(0) %.17g\n",
           wall_gamma_c4(0.0), wall_moment2_c4(0.0), wall_moment_yy_c4(0.0));
    fail = 1;
  }
  printf(
      "wall C4 3-D: max rel error (tol 1e-10) gamma %.3e, h|grad gamma| %.3e, moment2 %.3e, "
      "moment_yy %.3e\n",
      e_max[0], e_max[1], e_max[2], e_max[3]);
  return fail;
}

/** Minimal fixed-seed LCG in [0, 1). */
static unsigned long long lcg_state = 0x2545F4914F6CDD1DULL;
static double lcg_uniform(void) {
  lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  gauss_legendre(GL_N, gl_x, gl_w);
  int fail = 0;

  /* closed forms against quadrature */
  for (int dim = 2; dim <= 3; dim++) {
    const double atol = dim == 2 ? ATOL_2D : 0.0;
    double e_rel[3] = {0.0, 0.0, 0.0}, q_rel[3] = {0.0, 0.0, 0.0}, e_abs[3] = {0.0, 0.0, 0.0};
    double e_tail[3] = {0.0, 0.0, 0.0}, e_quad = 0.0;
    for (int iq = 1; iq < 100; iq++) {
      const double q = 0.02 * iq;
      double r1[3], r2[3];
      reference(dim, q, 24, &r1[0], &r1[1], &r1[2]);
      reference(dim, q, 48, &r2[0], &r2[1], &r2[2]);
      const double val[3] = {wall_gamma(dim, q), wall_dgamma(dim, q), wall_moment2(dim, q)};
      int bad = 0;
      for (int j = 0; j < 3; j++) {
        const double eq = rel_err(r1[j], r2[j]);
        if (eq > e_quad) e_quad = eq;
        if (!(eq <= 1e-13)) {
          printf("FAIL: dim %d q %.2f: quadrature not converged (24 vs 48 panels: %.3e)\n", dim, q,
                 eq);
          bad = 1;
        }
        const double ea = fabs(val[j] - r2[j]), er = ea / fabs(r2[j]);
        /* gamma and |grad gamma| (the acceptance quantities) are held to 1e-10 relative
           everywhere; only the 2-D moment2 keeps the absolute floor near q = 2 */
        const double fl = j == 2 ? atol : 0.0;
        if (ea > e_abs[j]) e_abs[j] = ea;
        if (1e-10 * fabs(r2[j]) >= fl) { /* the absolute floor is immaterial here */
          if (er > e_rel[j]) e_rel[j] = er, q_rel[j] = q;
        } else if (er > e_tail[j]) {
          e_tail[j] = er;
        }
        if (!(ea <= 1e-10 * fabs(r2[j]) + fl)) bad = 1;
      }
      if (bad) {
        printf(
            "FAIL: dim %d q %.2f: gamma %.17g vs %.17g, dgamma %.17g vs %.17g, "
            "moment2 %.17g vs %.17g\n",
            dim, q, val[0], r2[0], val[1], r2[1], val[2], r2[2]);
        fail = 1;
      }
    }
    printf(
        "wall %d-D: max rel error (tol 1e-10) gamma %.3e (q=%.2f), h|grad gamma| %.3e "
        "(q=%.2f), moment2 %.3e (q=%.2f)\n",
        dim, e_rel[0], q_rel[0], e_rel[1], q_rel[1], e_rel[2], q_rel[2]);
    printf("wall %d-D: max abs error gamma %.3e, h|grad gamma| %.3e, moment2 %.3e", dim, e_abs[0],
           e_abs[1], e_abs[2]);
    if (dim == 2)
      printf(
          " (atol %.0e); rel error where the value < 1e4 atol (q -> 2, cancellation): "
          "%.3e, %.3e, %.3e",
          atol, e_tail[0], e_tail[1], e_tail[2]);
    printf("\nwall %d-D: quadrature self-check 24 vs 48 panels %.3e (tol 1e-13)\n", dim, e_quad);

    /* endpoints */
    const double ends[][2] = {{wall_gamma(dim, 0.0), 0.5},          {wall_gamma(dim, 2.0), 1.0},
                              {wall_gamma(dim, 2.5), 1.0},          {wall_dgamma(dim, 2.0), 0.0},
                              {wall_moment2(dim, 0.0), -0.5 * dim}, {wall_moment2(dim, 2.0), 0.0}};
    const char *names[] = {"gamma(0)",  "gamma(2)",   "gamma(2.5)",
                           "dgamma(2)", "moment2(0)", "moment2(2)"};
    for (int i = 0; i < 6; i++)
      if (!(fabs(ends[i][0] - ends[i][1]) <= 1e-15)) {
        printf("FAIL: dim %d: %s = %.17g, expected %g\n", dim, names[i], ends[i][0], ends[i][1]);
        fail = 1;
      }
    /* small q is continuous with the q = 0 values (2-D special-cases q <= 0) */
    double g, d, m;
    reference(dim, 1e-3, 48, &g, &d, &m);
    const double e0 =
        fmax(rel_err(wall_gamma(dim, 1e-3), g),
             fmax(rel_err(wall_dgamma(dim, 1e-3), d), rel_err(wall_moment2(dim, 1e-3), m)));
    if (!(e0 <= 1e-10)) {
      printf("FAIL: dim %d q = 1e-3: max rel error %.3e\n", dim, e0);
      fail = 1;
    }
    printf(
        "wall %d-D: endpoints gamma(0) = %.17g, gamma(2) = %.17g, moment2(0) = %.17g; "
        "q = 1e-3 rel error %.3e\n",
        dim, wall_gamma(dim, 0.0), wall_gamma(dim, 2.0), wall_moment2(dim, 0.0), e0);
  }

  /* 2-D: segments covering the whole line sum to the full line integral */
  const double seg_len[] = {0.3, 0.77};
  double e_seg = 0.0, q_seg = 0.0, a_seg = 0.0;
  for (int il = 0; il < 2; il++)
    for (int iq = 1; iq < 100; iq++)
      for (int trial = 0; trial < 5; trial++) {
        const double q = 0.02 * iq, len = seg_len[il], ref = wall_dgamma(2, q);
        const double s0 = -2.5 - len * lcg_uniform(); /* starts outside the support */
        double sum = 0.0;
        for (int i = 0;; i++) {
          const double a = s0 + i * len, b = s0 + (i + 1) * len;
          sum += wall_segment_2d(q, a, b);
          if (b > 2.5) break;
        }
        const double ea = fabs(sum - ref);
        if (ea > a_seg) a_seg = ea;
        if (1e-12 * ref >= ATOL_2D && ea / ref > e_seg) e_seg = ea / ref, q_seg = q;
        if (!(ea <= 1e-12 * ref + ATOL_2D)) {
          printf("FAIL: segments of %.2f, q %.2f, offset %.6f: sum %.17g vs dgamma %.17g\n", len, q,
                 s0, sum, ref);
          fail = 1;
        }
      }
  /* one segment over the whole support, and segments entirely outside it */
  for (int iq = 1; iq < 100; iq++) {
    const double q = 0.02 * iq, ref = wall_dgamma(2, q);
    const double ea = fabs(wall_segment_2d(q, -3.0, 3.0) - ref);
    if (ea > a_seg) a_seg = ea;
    if (1e-12 * ref >= ATOL_2D && ea / ref > e_seg) e_seg = ea / ref, q_seg = q;
    if (!(ea <= 1e-12 * ref + ATOL_2D) || wall_segment_2d(q, 2.0, 2.7) != 0.0 ||
        wall_segment_2d(q, -2.7, -2.0) != 0.0) {
      printf("FAIL: q %.2f: whole-line segment error %.3e or outside segment != 0\n", q, ea);
      fail = 1;
    }
  }
  printf(
      "wall 2-D: sum of wall_segment_2d vs wall_dgamma: max rel error %.3e (q=%.2f, "
      "tol 1e-12), max abs error %.3e (atol %.0e)\n",
      e_seg, q_seg, a_seg, ATOL_2D);

  fail |= check_c4();
  printf("%s\n", fail ? "test_wall: FAILED" : "test_wall: passed");
  MPI_Finalize();
  return fail;
}
