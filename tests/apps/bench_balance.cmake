# `cohort bench balance` end to end on a short run: table, JSON and plot are written and every balancer
# appears; unknown balancers and real tracers this build cannot provide fail with the reason.
add_test(NAME apps.bench_balance_short
         COMMAND cohort bench balance --frames 24 --tracers 2,3 --json ${CMAKE_BINARY_DIR}/bench_balance_test.json
                 --plot ${CMAKE_BINARY_DIR}/bench_balance_test.png)
set_tests_properties(apps.bench_balance_short PROPERTIES LABELS apps
                     PASS_REGULAR_EXPRESSION "robin-hood.*perfect-smooth.*row-cost.*wrote .*bench_balance_test.json.*wrote .*bench_balance_test.png")
add_test(NAME apps.bench_balance_unknown_balancer COMMAND cohort bench balance --frames 4 --balancers fastest)
set_tests_properties(apps.bench_balance_unknown_balancer PROPERTIES LABELS apps WILL_FAIL TRUE)
add_test(NAME apps.bench_balance_real_tracer_missing COMMAND cohort bench balance --frames 4 --real no-such-tracer)
set_tests_properties(apps.bench_balance_real_tracer_missing PROPERTIES LABELS apps
                     PASS_REGULAR_EXPRESSION "cohort bench balance: .*no-such-tracer")
