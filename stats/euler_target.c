/**
 * @file euler_target.c
 * @brief The Eulerian engine's word on convergence: its line for the log, the indicators of
 *        a turbulent result and the standard errors against a convergence target.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc.h"
#include "euler.h"
#include "moments.h"

void euler_target_progress(const struct euler *e, const struct euler_target *tg,
                           struct euler_progress *p) {
  memset(p, 0, sizeof *p);
  p->rel_u = p->rel_uv = p->worst = p->ratio = p->windows_needed = p->t_reach = NAN;
  if (!e || euler_rows(e) == 0) return;
  struct euler_result r;
  euler_running_result(e, &r);
  double se = 0.0, umax = 0.0, uv = 0.0, se_uv = NAN;
  for (int b = 0; b < r.nb; b++) {
    if (isfinite(r.prof[EP_SE_U][b])) se = fmax(se, r.prof[EP_SE_U][b]);
    if (isfinite(r.prof[EP_U][b])) umax = fmax(umax, fabs(r.prof[EP_U][b]));
    if (isfinite(r.prof[EP_UV][b]) && fabs(r.prof[EP_UV][b]) > uv)
      uv = fabs(r.prof[EP_UV][b]), se_uv = r.prof[EP_SE_U + 8][b]; /* stderr of uv */
  }
  p->windows = r.n_batches;
  const double win = e->cfg.window;
  p->ratio = win / r.corr_time;
  if (r.n_batches >= 2) {
    p->rel_u = umax > 0.0 ? se / umax : NAN;
    p->rel_uv = uv > 0.0 ? se_uv / uv : NAN;
    p->worst = tg->profiles == 1   ? p->rel_u
               : tg->profiles == 2 ? p->rel_uv
                                   : fmax(p->rel_u, p->rel_uv);
    if (tg->profiles == 0 && (isnan(p->rel_u) || isnan(p->rel_uv))) p->worst = NAN;
  }
  if (isfinite(p->worst)) {
    const double q = p->worst / tg->rel_stderr;
    p->windows_needed = fmax((double)tg->windows, ceil(r.n_batches * q * q));
    p->t_reach = e->win[WIN_T0] + p->windows_needed * win;
  }
  p->met = r.n_batches >= tg->windows && isfinite(p->worst) && p->worst <= tg->rel_stderr &&
           (tg->corr_ratio <= 0.0 || p->ratio >= tg->corr_ratio);
  euler_result_free(&r);
}

void euler_turbulence(const struct euler_config *c, const struct euler_result *r,
                      struct euler_turb *t) {
  const double ut = r->u_tau > 0.0 ? r->u_tau : r->u_tau_force, ut2 = ut * ut;
  t->uv_peak = t->y_peak = t->r_uv = t->pair_share = t->resolved_share = NAN;
  double rsum = 0.0, best = INFINITY;
  int rn = 0;
  for (int b = 0; b < r->nb; b++) {
    const double y = r->prof[EP_Y_MEAN][b], up = !c->fold && y > c->delta;
    const double yp = (up ? 2.0 * c->delta - y : y) * ut / c->nu;
    const double muv = (up ? 1.0 : -1.0) * r->prof[EP_UV][b]; /* -u'v' towards the centre */
    if (!isfinite(muv) || !(ut2 > 0.0)) continue;
    if (!(muv / ut2 <= t->uv_peak)) t->uv_peak = muv / ut2, t->y_peak = yp;
    const double rms = sqrt(r->prof[EP_UU][b] * r->prof[EP_VV][b]);
    if (yp >= 30.0 && yp <= 100.0 && rms > 0.0) rsum += muv / rms, rn++;
    const double tot = r->prof[EP_TOTAL][b];
    if (r->budget && fabs(yp - 30.0) < best && fabs(tot) > 0.0) { /* the bin nearest y+ = 30 */
      best = fabs(yp - 30.0);
      t->pair_share = r->prof[EP_TAU_PAIR][b] / tot;
      t->resolved_share = r->prof[EP_TAU_REYNOLDS][b] / tot;
    }
  }
  if (rn) t->r_uv = rsum / rn;
}

void euler_log(const struct euler *e, char *buf, size_t len) {
  buf[0] = '\0';
  if (euler_rows(e) == 0) return;
  struct euler_result r;
  euler_running_result(e, &r);
  double se = 0.0, umax = 0.0;
  for (int b = 0; b < r.nb; b++) {
    if (isfinite(r.prof[EP_SE_U][b])) se = fmax(se, r.prof[EP_SE_U][b]);
    if (isfinite(r.prof[EP_U][b])) umax = fmax(umax, fabs(r.prof[EP_U][b]));
  }
  const double win = e->cfg.window;
  /* the windows in eddy turnovers delta/u_tau of the driving force */
  const double ett = r.u_tau_force > 0.0 ? r.n_batches * win * r.u_tau_force / e->cfg.delta : NAN;
  snprintf(buf, len,
           "stats: %d complete windows of %.4g s (%.3g turnovers), %.0f snapshots; correlation "
           "time %.3g s (window/corr %.3g); max stderr(u_mean) %.3g m/s (%.3g%% of max u_mean); "
           "u_tau wall %.6g force %.6g%s\n",
           r.n_batches, win, ett, r.snapshots, r.corr_time, win / r.corr_time, se,
           umax > 0 ? 100 * se / umax : NAN, r.u_tau_wall, r.u_tau_force,
           r.n_batches < 2           ? " (fewer than 2 windows: no error bars yet)"
           : win < 5.0 * r.corr_time ? " (windows shorter than 5 correlation times: error bars "
                                       "too small; increase stats.window)"
                                     : "");
  /* is it turbulent? the -u'v' peak and R_uv of the last window, the budget's split at y+ 30 */
  struct euler_turb all, last;
  euler_turbulence(&e->cfg, &r, &all);
  euler_result_free(&r);
  const size_t rows = euler_rows(e), r0 = e->nwin > 0 ? e->nwin - 1 : 0; /* last complete */
  int *complete = mem_alloc(rows, sizeof(int), "Eulerian statistics");
  for (size_t w = 0; w < rows; w++) complete[w] = w < e->nwin;
  euler_finalise(&e->cfg, e->win, e->mom, e->snp, e->pln, e->kin, e->rsb, e->tpl, e->tkn, complete,
                 r0, r0 + 1, &r);
  euler_turbulence(&e->cfg, &r, &last);
  euler_result_free(&r);
  free(complete);
  const size_t used = strlen(buf);
  if (used > 0 && used < len) buf[used - 1] = ';';
  snprintf(buf + used, len - used,
           " turbulence (last window): -u'v'+ peak %.3g at y+ %.3g, R_uv(30<y+<100) %.3g; "
           "average -u'v'+ peak %.3g; stress at y+ 30: resolved %.0f%%, pair (numerical) "
           "%.0f%%\n",
           last.uv_peak, last.y_peak, last.r_uv, all.uv_peak, 100.0 * all.resolved_share,
           100.0 * all.pair_share);
}
