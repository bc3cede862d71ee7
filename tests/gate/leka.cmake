# Gate tests: leka (see CMakeLists.txt for hil_add_gate_test).
#
# The Leka robot's external-client gate: tests/gate/clients/leka_good.py,
# a client written from the robot's protocol page and the contract, passes
# the gate's Leka scenarios (and the library's); the same client with one
# realistic bug planted (`--bug NAME`) is rejected by the scenario that
# guards that rule, with a message that names the symptom, and passes the
# scenarios that guard the others where the bug does not reach them. leka-client has no mode that
# reads operator actions on stdin (it runs a whole script, read before
# anything is sent), so it is not run here.

set(leka_pacing tests/gate/scenarios/leka-gate-buffer-pacing.yaml)
set(leka_checksum tests/gate/scenarios/leka-gate-checksum.yaml)
set(leka_length tests/gate/scenarios/leka-gate-group-length.yaml)
set(leka_gate_scenarios ${leka_pacing} ${leka_checksum} ${leka_length})
set(leka_good "python3 ${gate_clients}/leka_good.py {pty}")
set(leka_bug "python3 ${gate_clients}/leka_good.py {pty} --bug")
set(leka_no_crash
    [=[the client exited with code|the client was ended by signal|the client is not running|Traceback]=])

# The gate's Leka scenarios hold with hil's reference client in virtual
# time, so their expectations are right, not merely loose.
hil_add_gate_test(leka-scenarios-pass-with-the-reference-client TIMEOUT 60 CHECK
  --exit 0 --expect [=[^3 passed, 0 failed$]=]
  -- $<TARGET_FILE:hil> run ${leka_gate_scenarios})

# The correct client passes every one of them in real time.
hil_add_gate_test(leka-good-client-passes TIMEOUT 60 CHECK
  --exit 0 --expect [=[^3 passed, 0 failed$]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run ${leka_gate_scenarios} -j 2 --client-exec ${leka_good})

# And the library's Leka scenarios, written for the reference client in
# virtual time: with the slack of a real-time run, their windows counted
# from the client's first connection and their steps begun when it opens
# the port, the same client passes them too, started 2 s late as an
# interpreter or a JVM may be.
hil_add_gate_test(leka-good-client-started-2s-late-passes-the-library-scenarios TIMEOUT 60 CHECK
  --exit 0 --expect [=[^4 passed, 0 failed$]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run scenarios/leka -j 2
     --client-exec "${gate_clients}/slow_start.sh 2 ${leka_good}")

# Frames filled to the spec's 128 bytes and written as fast as the port
# takes them: two 81-byte frames end within one 10 ms pass, the robot's
# 128-byte buffer overflows, and the infos whose bytes were lost are never
# answered. The frames themselves are right, so the other two scenarios
# pass.
hil_add_gate_test(leka-no-pacing-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^leka-gate-buffer-pacing +FAIL]=]
  --expect [=[^leka-gate-checksum +PASS]=]
  --expect [=[^leka-gate-group-length +PASS]=]
  --expect [=[(?s)^FAIL leka-gate-buffer-pacing .*?\(belt single 0 255 0 0\x3b [^\n]*\) failed at [0-9.]+ s: info: no answer within 200 ms.*?\(the robot answered all six infos of the show \(a frame that lost bytes in the full 128-byte buffer is never answered\)\): expected exactly 6 'client received reply'[^\n]*found [0-5]\b.*?^  repeat: ]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run ${leka_gate_scenarios} -j 2 --client-exec "${leka_bug} no-pacing")

# The checksum summed over the length byte and the group, as the spec's
# prose says: right by luck for groups of up to 8 bytes (the length's bits
# are rotated out of the low byte), wrong for the 13-byte group, which the
# robot drops. Every group of leka-gate-group-length is 8 bytes or fewer,
# so that scenario passes.
hil_add_gate_test(leka-length-in-checksum-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^leka-gate-checksum +FAIL]=]
  --expect [=[^leka-gate-group-length +PASS]=]
  --expect [=[(?s)^FAIL leka-gate-checksum .*?\(the 13-byte group reached the robot with its checksum 70, the BSD sum of the command group alone\): expected at least one 'car received led.ear.all \(valid\)[^\n]*found none.*?\(no frame reached the robot with a wrong checksum \(it drops such a frame in silence\)\): expected no 'car received a frame \(invalid\) with error checksum'[^\n]*found 1\b.*?^  repeat: ]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run ${leka_checksum} ${leka_length} -j 2
     --client-exec "${leka_bug} length-in-checksum")

# The length byte counting only the group's first command: a single command
# goes out right, a group of two is cut short, its checksum read from the
# middle of the group, and the robot drops it and does not drive.
hil_add_gate_test(leka-first-command-length-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^leka-gate-group-length +FAIL]=]
  --expect [=[(?s)^FAIL leka-gate-group-length .*?\(the two-command group reached the robot as one whole frame, its length byte 07 counting all 7 group bytes\): expected at least one 'car received led.ear.all \(valid\)[^\n]*found none.*?\(and the robot ran its motor command, driving within 0.5 s\): expected at least one 'chassis moving'[^\n]*found none.*?\(the robot dropped no frame as damaged [^\n]*\): expected no 'car received a frame \(invalid\)'[^\n]*found [1-9].*?^  repeat: ]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run ${leka_length} --client-exec "${leka_bug} first-command-length")

# The port closed at the end of the input with the motors still running:
# the robot cannot tell that its link went away and turns on, and hil's
# end-of-run check finds it still driven after the client exited.
hil_add_gate_test(leka-no-stop-at-exit-client-is-rejected TIMEOUT 60 CHECK
  --exit 1
  --expect [=[^leka-gate-group-length +FAIL]=]
  --expect [=[(?s)^FAIL leka-gate-group-length .*?\(the car at rest [0-9.]+ s after the client exited\): the car was still moving [^\n]*its motors driven.*?^  repeat: ]=]
  --reject ${leka_no_crash}
  -- $<TARGET_FILE:hil> run ${leka_length} --client-exec "${leka_bug} no-stop-at-exit")

# The flakiness hunt: 20 runs of each scenario, two at a time, all pass.
# About 90 s on the shared two-core machine, over the gate's time budget,
# so it runs with the soak tests (`ctest -C soak -L soak`), not in the
# default stage.
hil_add_gate_soak_test(leka-good-client-passes-20-repeats TIMEOUT 600 CHECK
  --exit 0
  --count 60 [=[^leka-gate-[a-z-]+ #[0-9]+ +PASS ]=]
  --expect [=[^3 passed, 0 failed$]=]
  --reject [=[^leka-gate-[a-z-]+ #[0-9]+ +(FAIL|FLAKY)]=]
  -- $<TARGET_FILE:hil> run ${leka_gate_scenarios} --repeat 20 -j 2 --client-exec ${leka_good})
