# Gate tests: arduino (see CMakeLists.txt for hil_add_gate_test).
#
# The Arduino robot's external-client gate: tests/gate/clients/arduino_good.py,
# a client written from the robot's protocol page and the contract, passes
# the gate's Arduino scenarios; the same client with one realistic bug
# planted (`--bug NAME`) is rejected by the scenario that guards that rule,
# with a message that names the symptom. The pipelining bug's tests are in
# CMakeLists.txt (arduino_pipelining_bug.py). arduino-client has no mode
# that reads operator actions on stdin, so it is not run here.

set(bad_cs_resend tests/gate/scenarios/arduino-gate-bad-cs-resend.yaml)
set(stale_reply tests/gate/scenarios/arduino-gate-stale-reply.yaml)
set(retry_backoff tests/gate/scenarios/arduino-gate-retry-backoff.yaml)
set(stop_at_exit tests/gate/scenarios/arduino-gate-stop-at-exit.yaml)
set(arduino_gate_scenarios ${one_request} ${bad_cs_resend} ${stale_reply} ${retry_backoff}
    ${stop_at_exit})
set(arduino_bug "python3 ${gate_clients}/arduino_good.py {pty} --bug")
set(arduino_no_crash
    [=[the client exited with code|the client was ended by signal|the client is not running|Traceback]=])

# The gate's Arduino scenarios hold with hil's reference client in virtual
# time, so their expectations are right, not merely loose.
hil_add_gate_test(arduino-scenarios-pass-with-the-reference-client TIMEOUT 60 CHECK
  --exit 0 --expect [=[^5 passed, 0 failed$]=]
  -- $<TARGET_FILE:hil> run ${arduino_gate_scenarios})

# The correct client passes every one of them in real time, started 2 s
# late as an interpreter or a JVM may be: a serial car's steps begin when
# the program opens the port (docs/scenarios.md, "The origin"), so its
# start-up counts against no window. (The scenarios the bug tests below
# expect to pass run it without the delay.)
hil_add_gate_test(arduino-good-client-started-2s-late-passes TIMEOUT 60 CHECK
  --exit 0 --expect [=[^5 passed, 0 failed$]=]
  --reject ${arduino_no_crash}
  -- $<TARGET_FILE:hil> run ${arduino_gate_scenarios} -j 3
     --client-exec "${gate_clients}/slow_start.sh 2 ${arduino_good}")

# NACK BAD_CS taken for a refusal: V 160 fails with the board's code and is
# never resent.
hil_add_gate_test(arduino-no-bad-cs-resend-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^arduino-gate-bad-cs-resend +FAIL]=]
  --expect [=[(?s)^FAIL arduino-gate-bad-cs-resend .*?step line [0-9]+ \(V 160\) failed at [0-9.]+ s: NACK BAD_CS.*?\(V was resent at once after NACK BAD_CS, not after a timeout\): expected at least one 'car received V \(valid\)[^\n]*found none.*?^  repeat: ]=]
  --reject ${arduino_no_crash}
  -- $<TARGET_FILE:hil> run ${bad_cs_resend} --client-exec "${arduino_bug} no-bad-cs-resend")

# The next reply taken for the answer whatever its SEQ: the duplicated PONG
# ends V 160 before the board has answered it, and M 20 goes out early.
hil_add_gate_test(arduino-any-seq-answer-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^arduino-gate-stale-reply +FAIL]=]
  --expect [=[(?s)^FAIL arduino-gate-stale-reply .*?\(V 160 ended only once the board's own answer to V had left it, not on the stale second PONG\): expected exactly 1 'action 'V 160' succeeded'[^\n]*found none[^\n]*early.*?\(M 20 reached the robot only after V's answer had left it\): expected exactly 1 'car received M'[^\n]*found none.*?^  repeat: ]=]
  --reject ${arduino_no_crash}
  -- $<TARGET_FILE:hil> run ${stale_reply} --client-exec "${arduino_bug} any-seq-answer")

# A timeout that never doubles: the third PING goes out 1.2 s after the
# first, not 1.8 s.
hil_add_gate_test(arduino-fixed-timeout-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^arduino-gate-retry-backoff +FAIL]=]
  --expect [=[(?s)^FAIL arduino-gate-retry-backoff .*?\(PING attempts 0.6 s and then 1.2 s apart, the timeout doubling on each retry\): expected 'client sent PING' only at [^\n]*nothing at [0-9.]+ s, the nearest at [0-9.]+ s, 0\.[4-8][0-9]* s early\x3b 1 more outside those times.*?^  repeat: ]=]
  --reject ${arduino_no_crash}
  -- $<TARGET_FILE:hil> run ${retry_backoff} --client-exec "${arduino_bug} fixed-timeout")

# The port closed at the end of the input with M 100 still running, no S:
# rejected by the run's end check (the car still moving after the exit).
hil_add_gate_test(arduino-no-stop-at-exit-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^arduino-gate-stop-at-exit +FAIL]=]
  --expect [=[(?s)^FAIL arduino-gate-stop-at-exit .*?: the car was still moving [0-9.]+ s after the client exited [^\n]*a client stops the car when its input ends.*?^  repeat: ]=]
  --reject ${arduino_no_crash}
  -- $<TARGET_FILE:hil> run ${stop_at_exit} --client-exec "${arduino_bug} no-stop-at-exit")

# The flakiness hunt: 20 runs of each scenario, two at a time, all pass.
# About two minutes, so it runs with the soak tests (`ctest -C soak -L
# soak`), not in the default stage.
hil_add_gate_soak_test(arduino-good-client-passes-20-repeats TIMEOUT 600 CHECK
  --exit 0
  --count 100 [=[^arduino-gate-[a-z-]+ #[0-9]+ +PASS ]=]
  --expect [=[^5 passed, 0 failed$]=]
  --reject [=[^arduino-gate-[a-z-]+ #[0-9]+ +(FAIL|FLAKY)]=]
  -- $<TARGET_FILE:hil> run ${arduino_gate_scenarios} --repeat 20 -j 2
     --client-exec ${arduino_good})

# The library's own Arduino scenarios with the same client, started 2 s
# late: every one passes. About 45 s.
hil_add_gate_soak_test(arduino-library-passes-the-python-client-started-2s-late TIMEOUT 600 CHECK
  --exit 0 --expect [=[^11 passed, 0 failed$]=]
  -- $<TARGET_FILE:hil> run scenarios/arduino -j 2
     --client-exec "${gate_clients}/slow_start.sh 2 ${arduino_good}")
