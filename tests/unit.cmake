# Unit tests of solver components (label: unit, a few seconds in all); included from
# tests/CMakeLists.txt.
#   test_kernel: Wendland kernel normalisation, gradient factor, support (thesis Eq. 2.63-2.66)
#   test_wall:   plane-wall gamma, |grad gamma|, second moment (thesis Eq. 4.9-4.11, 2-D
#                analogues) against quadrature; Ferrand Eq. 51-52 segments
#   test_nbr:    cell-list neighbour search against brute force, sort order and permutation
#   test_reduce: deterministic blocked sums, bitwise across thread counts
#   test_turb:   model terms (strain, van Driest, Smagorinsky, Yoshizawa, Violeau-Issa,
#                wall-law stresses, Violeau wall moment) against closed forms
#   test_walllaw: wall-law friction velocity (thesis Eq. 2.146, 5.51, 5.53): residual over
#                y+ 1e-6..1e6, any speed and viscosity

add_executable(test_kernel test_kernel.c)
target_link_libraries(test_kernel PRIVATE chansph_core)
add_test(NAME unit_kernel COMMAND test_kernel)
set_tests_properties(unit_kernel PROPERTIES LABELS unit)

add_executable(test_wall test_wall.c)
target_link_libraries(test_wall PRIVATE chansph_core)
add_test(NAME unit_wall COMMAND test_wall)
set_tests_properties(unit_wall PROPERTIES LABELS unit)

add_executable(test_nbr test_nbr.c)
target_link_libraries(test_nbr PRIVATE chansph_core)
add_test(NAME unit_nbr COMMAND test_nbr)
set_tests_properties(unit_nbr PROPERTIES LABELS unit)

add_executable(test_reduce test_reduce.c)
target_link_libraries(test_reduce PRIVATE chansph_core)
add_test(NAME unit_reduce COMMAND test_reduce)
set_tests_properties(unit_reduce PROPERTIES LABELS unit)

add_executable(test_sph test_sph.c)
target_link_libraries(test_sph PRIVATE chansph_core)
add_test(NAME unit_sph COMMAND test_sph)
set_tests_properties(unit_sph PROPERTIES LABELS unit)

#   test_stats:  statistics engine: known synthetic fields, merge invariance, state round trip
add_executable(test_stats test_stats.c)
target_link_libraries(test_stats PRIVATE chansph_core)
target_include_directories(test_stats PRIVATE ${PROJECT_SOURCE_DIR}/stats)
add_test(NAME unit_stats COMMAND test_stats)
set_tests_properties(unit_stats PROPERTIES LABELS unit)

#   test_pdf:  one-point PDF engine: known distributions, standard errors, stats.nc read back
add_executable(test_pdf test_pdf.c)
target_link_libraries(test_pdf PRIVATE chansph_core)
add_test(NAME unit_stats_pdf COMMAND test_pdf)
set_tests_properties(unit_stats_pdf PROPERTIES LABELS unit)

add_executable(test_walllaw test_walllaw.c)
target_link_libraries(test_walllaw PRIVATE chansph_core m)
add_test(NAME unit_walllaw COMMAND test_walllaw)
set_tests_properties(unit_walllaw PROPERTIES LABELS "unit;stability")

add_executable(test_turb test_turb.c)
target_link_libraries(test_turb PRIVATE chansph_core)
add_test(NAME unit_turb COMMAND test_turb)
set_tests_properties(unit_turb PROPERTIES LABELS unit)

# Taylor-Green check of the pressure gradient (thesis Sec. 6.2.2); the table and plot of
# docs/validation/taylor_green.md come from tests/taylor_green_doc.py
add_executable(taylor_green taylor_green.c)
target_link_libraries(taylor_green PRIVATE chansph_core)
add_test(NAME taylor_green_lattice COMMAND taylor_green --check)
add_test(NAME taylor_green_jittered COMMAND taylor_green --jitter 0.2 --check)
set_tests_properties(taylor_green_lattice taylor_green_jittered
                     PROPERTIES LABELS "validation;models")

# inviscid energy experiment of thesis Sec. 3.1.2 (stability case 2)
add_executable(energy_check energy_check.c)
target_link_libraries(energy_check PRIVATE chansph_core)
add_test(NAME stability_energy COMMAND energy_check --check)
set_tests_properties(stability_energy PROPERTIES LABELS "stability;validation")

#   test_init:   synthetic-eddy start-up (init.profile = synthetic) against the Lee & Moser 180
#                mean and Reynolds stresses, zero at the walls, bitwise across thread counts
add_executable(test_init test_init.c)
target_link_libraries(test_init PRIVATE chansph_core m)
add_test(NAME unit_init COMMAND test_init)
set_tests_properties(unit_init PROPERTIES LABELS unit)

#   test_shift:  particle shifting: the lattice at rest is an equilibrium (walls included), a
#                perturbed lattice is ordered by the shift (docs/theory.md, "Particle shifting")
add_executable(test_shift test_shift.c)
target_link_libraries(test_shift PRIVATE chansph_core)
add_test(NAME unit_shift COMMAND test_shift)
set_tests_properties(unit_shift PROPERTIES LABELS unit)

#   test_wall_collision: a particle sent through each wall in one step: the health check names
#                it (sph.wall_collision = stop), or it is mirrored in the wall, u and w kept,
#                every other particle bit-identical (reflect)
add_executable(test_wall_collision test_wall_collision.c)
target_link_libraries(test_wall_collision PRIVATE chansph_core m)
add_test(NAME unit_wall_collision COMMAND test_wall_collision)
set_tests_properties(unit_wall_collision PROPERTIES LABELS unit)

#   test_budget_parts: the budget parts of the force pass (x, y, z) add up to the acceleration,
#                the pair parts conserve momentum in each component, the walls' part lives
#                within 2h of the walls (docs/theory.md, "Momentum at the walls")
add_executable(test_budget_parts test_budget_parts.c)
target_link_libraries(test_budget_parts PRIVATE chansph_core m)
add_test(NAME unit_budget_parts COMMAND test_budget_parts ${CMAKE_SOURCE_DIR}/jobs/scenes)
set_tests_properties(unit_budget_parts PROPERTIES LABELS unit PASS_REGULAR_EXPRESSION "PASS"
  FAIL_REGULAR_EXPRESSION "FAIL")

# the acoustic damper against the bulk-viscous damping rate of a sound wave (term_damper.h)
add_executable(test_damper test_damper.c)
target_link_libraries(test_damper PRIVATE chansph_core)
add_test(NAME unit_damper COMMAND test_damper)
set_tests_properties(unit_damper PROPERTIES LABELS unit)
# the kgc pressure gradient (sph.pressure_gradient = kgc, term_pressure.h): a linear pressure on a
# disordered lattice, momentum conservation, a fluid at rest between the walls, against symmetric
add_executable(test_kgc test_kgc.c)
target_link_libraries(test_kgc PRIVATE chansph_core)
add_test(NAME unit_kgc COMMAND test_kgc)
set_tests_properties(unit_kgc PROPERTIES LABELS unit)

#   test_uncertainty: standard errors of the Lagrangian, quadrant and Eulerian engines against
#                the exact ones of synthetic AR(1) and Gaussian signals, within 20% (issue 43)
add_executable(test_uncertainty test_uncertainty.c)
target_link_libraries(test_uncertainty PRIVATE chansph_core)
add_test(NAME unit_stats_uncertainty COMMAND test_uncertainty)
set_tests_properties(unit_stats_uncertainty PROPERTIES LABELS unit)
