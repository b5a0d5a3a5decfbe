/**
 * @file stats_scene.c
 * @brief The engines' reading of the scene (struct stats_scene, contract.h): their own keys by
 *        their definitions, y+ levels as heights, the window length. Depends on nothing but the
 *        contract and base headers, so an engine that reads the scene depends on no other part
 *        of the statistics layer.
 */
#include "contract.h"
#include "error.h"

const struct scene_list *stats_scene_value(const struct stats_scene *sc,
                                           const struct scene_key_def *key) {
  for (int k = 0; k < sc->n_keys; k++)
    if (sc->key_def[k] == key) return &sc->key_value[k];
  die("statistics: the scene has no key %s.%s (is its engine in stats_engines?)", key->section,
      key->name);
}

int stats_scene_int(const struct stats_scene *sc, const struct scene_key_def *key) {
  if (key->type != SCENE_INT && key->type != SCENE_CHOICE)
    die("statistics: scene key %s.%s is not an integer", key->section, key->name);
  return (int)stats_scene_value(sc, key)->v[0];
}

double stats_scene_double(const struct stats_scene *sc, const struct scene_key_def *key) {
  if (key->type != SCENE_DOUBLE)
    die("statistics: scene key %s.%s is not a number", key->section, key->name);
  return stats_scene_value(sc, key)->v[0];
}

int stats_scene_list(const struct stats_scene *sc, const struct scene_key_def *key, double *v,
                     int max) {
  if (key->type != SCENE_LIST)
    die("statistics: scene key %s.%s is not a list", key->section, key->name);
  const struct scene_list *L = stats_scene_value(sc, key);
  for (int i = 0; i < L->n && i < max; i++) v[i] = L->v[i];
  return L->n;
}

int stats_scene_levels(const struct stats_scene *sc, const struct scene_key_def *key,
                       double *y_plus, double *y, int max) {
  const int held = stats_scene_list(sc, key, y_plus, max), n = held < max ? held : max;
  for (int l = 0; l < n; l++) y[l] = y_plus[l] * sc->nu / sc->u_tau;
  return n;
}

double stats_window_length(const double key, const double t_average_start, const double t_end) {
  if (key > 0.0) return key;
  const double span = (t_end - t_average_start) / 10;
  return span > 0.0 ? span : t_end > 0 ? t_end / 10 : 1.0;
}
