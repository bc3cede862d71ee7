# Gate tests: wr8 (see CMakeLists.txt for hil_add_gate_test).
#
# The WR8 vehicle's external-client gate, in its default profile
# (`document`): four gate scenarios, each guarding one rule of the car
# (its header says which); tests/gate/clients/wr8_good.py, a correct client
# written from docs/protocols/wr8.md, passes all four, and each of its
# `--bug NAME` forms (one realistic bug each) is rejected by the scenario
# of its rule, for the symptom that rule names. hil's own wr8-client has no
# mode that follows the contract (its interactive mode reads actions on
# stdin but prints no result line hil can read), so hil's side is its
# reference client library, which passes the same scenarios in virtual
# time with exact timing. Together these runs take about 40 s of wall time;
# the 20-repeat flakiness hunt (about 4 minutes) runs only under
# `ctest -C soak -L soak`.

set(wr8_login_first tests/gate/scenarios/wr8-gate-login-first.yaml)
set(wr8_by_coi tests/gate/scenarios/wr8-gate-answers-by-coi.yaml)
set(wr8_backoff tests/gate/scenarios/wr8-gate-reconnect-backoff.yaml)
set(wr8_split tests/gate/scenarios/wr8-gate-split-answers.yaml)
set(wr8_gate_scenarios ${wr8_login_first} ${wr8_by_coi} ${wr8_backoff} ${wr8_split})
set(wr8_py "python3 ${gate_clients}/wr8_good.py")
set(wr8_good "${wr8_py} {host} {port}")
# A run that the client broke by crashing or leaving early is no rejection.
set(wr8_not_a_crash
    [=[the client exited with code|the client was ended by signal|the client is not running|Traceback]=])

# The gate's WR8 scenarios hold with hil's reference client in virtual time,
# so their expectations are right, not merely loose.
hil_add_gate_test(wr8-scenarios-pass-with-the-reference-client TIMEOUT 60 CHECK
  --exit 0 --expect [=[^4 passed, 0 failed$]=]
  -- $<TARGET_FILE:hil> run ${wr8_gate_scenarios})

# The correct client passes all four, two at a time.
hil_add_gate_test(wr8-python-client-passes TIMEOUT 90 CHECK
  --exit 0
  --expect [=[^wr8-gate-login-first +PASS ]=]
  --expect [=[^wr8-gate-answers-by-coi +PASS ]=]
  --expect [=[^wr8-gate-reconnect-backoff +PASS ]=]
  --expect [=[^wr8-gate-split-answers +PASS ]=]
  --expect [=[^4 passed, 0 failed$]=]
  -- $<TARGET_FILE:hil> run ${wr8_gate_scenarios} -j 2 --client-exec ${wr8_good})

# A client whose `connect` succeeds once AUTH is written, without waiting
# for the AUTH-REPLY: with the reply 400 ms on its way, its first TASK
# reaches the vehicle before the login was answered, and it calls itself
# connected before it was.
hil_add_gate_test(wr8-task-before-login-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^wr8-gate-login-first +FAIL]=]
  --expect [=[(?s)^FAIL wr8-gate-login-first .*?\(no TASK before the login was answered[^)]*\): expected exactly 3 'car received TASK' [^\n]*\(after client received AUTH_REPLY\)[^\n]*found [0-2]\b.*?\(the client reported itself connected only once the AUTH-REPLY had reached it\): expected exactly 1 'client connected'[^\n]*found none.*?^  repeat: ]=]
  --reject ${wr8_not_a_crash}
  -- $<TARGET_FILE:hil> run ${wr8_login_first}
     --client-exec "${wr8_py} --bug task-before-login {host} {port}")

# A client that gives every RESPONSE to its newest open request: the
# blink's answer completes the drive 1 m short, and the drive's answer
# completes the blink 1.6 s late.
hil_add_gate_test(wr8-newest-task-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^wr8-gate-answers-by-coi +FAIL]=]
  --expect [=[(?s)^FAIL wr8-gate-answers-by-coi .*?\(the blink was reported completed 2 s after it started, when the vehicle answered the blink's COI\): [^\n]*found none of them\x3b nothing at [^\n]*s late.*?\(the drive was reported completed only once the vehicle's DATA showed 90 of its 100 cm driven\): expected exactly 1 'client command drive completed'[^\n]*found none\x3b the nearest at [^\n]*s early.*?^  repeat: ]=]
  --reject ${wr8_not_a_crash}
  -- $<TARGET_FILE:hil> run ${wr8_by_coi} --client-exec "${wr8_py} --bug newest-task {host} {port}")

# A client that reconnects every 100 ms instead of after 1 s, 2 s, 4 s:
# tens of attempts where three are allowed, tens of connections turned away.
hil_add_gate_test(wr8-reconnect-without-backoff-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^wr8-gate-reconnect-backoff +FAIL]=]
  --expect [=[(?s)^FAIL wr8-gate-reconnect-backoff .*?\(attempts 1 s, 3 s and 7 s after the reset \(1 s, 2 s and 4 s after each failure\), and no others\): [^\n]*\x3b [0-9]{2,} more outside those times.*?\(two connections turned away\): expected exactly 2 'fault refuse'[^\n]*found [0-9]{2,}:.*?^  repeat: ]=]
  --reject ${wr8_not_a_crash}
  -- $<TARGET_FILE:hil> run ${wr8_backoff} --client-exec "${wr8_py} --bug no-backoff {host} {port}")

# A client that takes each read from the socket for one whole packet: the
# answers that come in pieces are lost and its first task times out.
hil_add_gate_test(wr8-one-read-one-packet-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^wr8-gate-split-answers +FAIL]=]
  --expect [=[(?s)^FAIL wr8-gate-split-answers .*?step line [0-9]+ \(task check\) failed at [^\n]*: no answer to the TASK or SETTINGS within 500 ms.*?\(no task timed out waiting for an answer that had come in pieces\): expected no 'client command \* timed_out'[^\n]*found 1.*?^  repeat: ]=]
  --reject ${wr8_not_a_crash}
  -- $<TARGET_FILE:hil> run ${wr8_split} --client-exec "${wr8_py} --bug one-read-one-packet {host} {port}")

# The flakiness hunt: 20 runs of each WR8 gate scenario, two at a time, all
# pass. It takes about 4 minutes, so it is a soak test: a plain `ctest`
# leaves it out, `ctest -C soak -L soak` runs it.
hil_add_gate_soak_test(wr8-python-client-passes-20-repeats TIMEOUT 900 CHECK
  --exit 0
  --count 20 [=[^wr8-gate-login-first #[0-9]+ +PASS ]=]
  --count 20 [=[^wr8-gate-answers-by-coi #[0-9]+ +PASS ]=]
  --count 20 [=[^wr8-gate-reconnect-backoff #[0-9]+ +PASS ]=]
  --count 20 [=[^wr8-gate-split-answers #[0-9]+ +PASS ]=]
  --expect [=[^4 passed, 0 failed$]=]
  --reject [=[^wr8-gate-[a-z-]+ #[0-9]+ +(FAIL|FLAKY)]=]
  -- $<TARGET_FILE:hil> run ${wr8_gate_scenarios} --repeat 20 -j 2 --client-exec ${wr8_good})

# The library's own WR8 scenarios (the document's dialect) with the same
# client, started 2 s late: every one passes but wr8-auth-wrong-string,
# which sets the reference client's login string and is skipped. About
# 2 minutes.
file(GLOB wr8_library RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS
     ${PROJECT_SOURCE_DIR}/scenarios/wr8/*.yaml)
hil_add_gate_soak_test(wr8-library-passes-the-python-client-started-2s-late TIMEOUT 900 CHECK
  --exit 0 --expect [=[^[0-9]+ passed, 0 failed, 1 skipped$]=]
  --expect [=[^SKIP wr8-auth-wrong-string ]=]
  -- $<TARGET_FILE:hil> run ${wr8_library} -j 2
     --client-exec "${gate_clients}/slow_start.sh 2 ${wr8_good}")
