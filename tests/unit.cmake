# Unit tests of solver components (label: unit, a few seconds in all); included from
# tests/CMakeLists.txt.
#   test_kernel: Wendland kernel normalisation, gradient factor, support (thesis Eq. 2.63-2.66)
#   test_wall:   plane-wall gamma, |grad gamma|, second moment (thesis Eq. 4.9-4.11, 2-D
#                analogues) against quadrature; Ferrand Eq. 51-52 segments
#   test_nbr:    cell-list neighbour search against brute force, sort order and permutation
#   test_reduce: deterministic blocked sums, bitwise across thread counts

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
