/**
 * @file stats_scene.c
 * @brief The engines' reading of the scene (struct stats_scene, contract.h): their own keys by
 *        name, and y+ levels as heights. Depends on nothing but the contract and base headers,
 *        so an engine that reads the scene depends on no other part of the statistics layer.
 */
#include "contract.h"
#include "error.h"

int stats_scene_list(const struct stats_scene *sc, const char *key, double *v, int max) {
  const int n = sc->get ? sc->get(sc->scene, key, v, max) : -1;
  if (n < 0) die("statistics: the scene has no numeric key %s", key);
  return n;
}

double stats_scene_num(const struct stats_scene *sc, const char *key) {
  double v = 0.0;
  if (stats_scene_list(sc, key, &v, 1) != 1) die("statistics: scene key %s is not a number", key);
  return v;
}

int stats_scene_levels(const struct stats_scene *sc, const char *key, double *y_plus, double *y,
                       int max) {
  const int held = stats_scene_list(sc, key, y_plus, max), n = held < max ? held : max;
  for (int l = 0; l < n; l++) y[l] = y_plus[l] * sc->nu / sc->u_tau;
  return n;
}

double stats_scene_window(const struct stats_scene *sc) {
  const double key = stats_scene_num(sc, "stats.window");
  if (key > 0.0) return key;
  const double span = (sc->t_end - sc->t_average_start) / 10;
  return span > 0.0 ? span : sc->t_end > 0 ? sc->t_end / 10 : 1.0;
}
