/**
 * @file engines.c
 * @brief The one list of the statistics engines (engine.h): the only place of the statistics
 *        layer that names them. An engine is added here with its header and one line.
 */
#include "engine.h"

#include "corr.h"
#include "euler.h"
#include "lagr.h"
#include "pdf.h"
#include "quad.h"

const struct stats_engine *const stats_engines[] = {&euler_engine, &corr_engine, &lagr_engine,
                                                    &quad_engine, &pdf_engine};
const int stats_n_engines = sizeof stats_engines / sizeof stats_engines[0];

_Static_assert(sizeof stats_engines / sizeof stats_engines[0] <= STATS_MAX_ENGINES,
               "struct stats has room for STATS_MAX_ENGINES engines (engine.h)");
