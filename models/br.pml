/*
 * railproof — on-board speed supervision decision: brake-level selection, emergency-brake
 * latch and release (D5 §5.5; spec/design/br.md §4; C++: br::Supervisor::Step,
 * cpp/runtime/br/src/supervisor.cpp).
 *
 * What is modelled. The decision of one supervision cycle and the state it keeps between
 * cycles: whether an emergency brake is latched, and the level commanded in the previous
 * cycle (NONE after an emergency-brake cycle, as in the C++). The pattern computation
 * (design note §3) is abstracted away: every cycle the environment chooses the supervised
 * speed v_s and the six pattern speeds v_e, v_7n, v_6n, v_5n, v_4n, v_release freely and
 * independently from 0..MODEL_VMAX (abstract speed units; spec/parameters/br.yaml).
 * The decision only compares v_s with each pattern speed, so the values need not be
 * ordered (design note §3: "the decision logic does not rely on it"): every order
 * relation, every equality and every "one above" boundary between v_s and each pattern
 * speed is among the choices, and the exhaustive search covers every combination in every
 * reachable state. The conformance harness feeds the abstract integers as mm/s, which is
 * exact since the decision only compares them.
 *
 * Driver and vehicle inputs: standstill, handle_emergency, reset are chosen freely every
 * cycle, with one constraint from design note §2: standstill implies v_s = 0 (standstill
 * means the measured speed has been zero for the standstill time, and then v_s = 0). The
 * converse is not assumed (v_s = 0 without standstill is allowed, an over-approximation
 * that costs nothing). So "moving" is "not at standstill", and every vector is physically
 * consistent (no vector claims standstill at a non-zero supervised speed).
 *
 * The cycle runs in the order of design note §4 (decide() below, step numbers as there).
 * Properties are evaluated by check() after every cycle on the state before it, the inputs,
 * the outputs and the state after it, into latched ghost bits v_*; each LTL property says
 * one of them never becomes 1. Inputs and outputs are cleared at the end of the cycle so
 * that the stored state is the supervisor's state only; the search is exhaustive over
 * unbounded runs.
 *
 * Configurations (-D): default = verification and trap goals (TRAPS adds the goal flags);
 * WALK stops after MODEL_CYCLES cycles (random-walk vectors). REALISABLE = the on-board
 * unit's environment: only the relations between v_s and the pattern speeds that the
 * braking module's pattern calculator can give at the unit's external interface (design note
 * spec/design/units.md, shown on the calculator by the property tests
 * BrakingPatternsProperty.EmergencyNeverBelowService and
 * .NoExceededRunBetweenLeadsWithinTheCeilingExtension): the emergency pattern exceeded only
 * with the service pattern exceeded (v_e >= v_7n), and of the five service points x_s (7N),
 * the 6N, 5N, 4N and release leads, the ones v_s exceeds form a prefix (a restriction's
 * ceiling released between two lead points) and a suffix (the stop limit or a restriction
 * ahead): the points not exceeded are one contiguous run. A variant (@variant below): every
 * property is verified there too (the environment never blocks a cycle), every goal is
 * searched again, and its goal and random-walk vectors are br.unit.jsonl, each of which the
 * unit-level replay drives through the on-board unit.
 *
 * Annotations read by testgen: see models/tg.pml.
 */
#include "br_params.pml"

#define VMAX MODEL_VMAX
#if MODEL_VMAX > 9 || MODEL_VMAX < 1
#error "CHOOSE below enumerates speeds 0..9: extend it for a larger MODEL_VMAX"
#endif

/* brake levels (br::BrakeLevel, in order) */
#define L_NONE 0
#define L_4N 1
#define L_5N 2
#define L_6N 3
#define L_7N 4
#define L_EB 5

/* ---- supervisor state (br::Supervisor members) ------------------------------------ */
bit latched;          /* emergency brake latched */
byte svc;             /* level commanded in the previous cycle (NONE after an EB cycle) */
/* ---- inputs of the cycle (cleared at its end) ------------------------------------------- */
byte vs, ve, v7, v6, v5, v4, vr;
bit st, he, rs;
/* ---- outputs of the cycle (cleared at its end) ------------------------------------------ */
byte level;
bit appr;
/* ---- scratch: the state at the start of the cycle (cleared at its end) ------------------ */
bit was_latched;
byte prev;
#ifdef WALK
byte ncycles;
#endif
#ifdef REALISABLE
/* ---- scratch of the unit's environment (cleared at the end of the cycle) --------------- */
bit must;             /* the next pattern speed picked must be exceeded by v_s */
byte phase;           /* service points so far: 0 all exceeded, 1 a run not exceeded began,
                       * 2 exceeded again after it (the rest must be exceeded) */
#endif
/* ---- ghost: latched property violations ----------------------------------------------- */
bit v_eb, v_latch, v_service, v_mild, v_release, v_ind;
#ifdef TRAPS
bit g[32];
byte h_i;
/* goal flags mark the goals reached in the last cycle only (cleared at the start of each
 * cycle), so that they do not multiply the states of the breadth-first trap searches */
#define GOAL(k) g[k] = 1
#define CLEAR_GOALS d_step { for (h_i : 0 .. 31) { g[h_i] = 0 }; h_i = 0 }
#else
#define CLEAR_GOALS skip
#define GOAL(k) skip
#endif

/* one speed, any value 0..VMAX, each a single transition (uniform in random walks);
 * REALISABLE: only values v_s exceeds while `must` is set (never empty: `must` follows an
 * exceeded pattern speed, so v_s >= 1 and 0 is always allowed) */
#ifdef REALISABLE
#define AND_OK(k) && (!must || vs > (k))
#else
#define AND_OK(k)
#endif
#define CHOOSE(x) \
  if \
  :: (VMAX >= 0 AND_OK(0)) -> x = 0 :: (VMAX >= 1 AND_OK(1)) -> x = 1 \
  :: (VMAX >= 2 AND_OK(2)) -> x = 2 :: (VMAX >= 3 AND_OK(3)) -> x = 3 \
  :: (VMAX >= 4 AND_OK(4)) -> x = 4 :: (VMAX >= 5 AND_OK(5)) -> x = 5 \
  :: (VMAX >= 6 AND_OK(6)) -> x = 6 :: (VMAX >= 7 AND_OK(7)) -> x = 7 \
  :: (VMAX >= 8 AND_OK(8)) -> x = 8 :: (VMAX >= 9 AND_OK(9)) -> x = 9 \
  fi
#define CHOOSE_BIT(b) if :: b = 0 :: b = 1 fi

#define RELEASE_ALL (st && he && rs)
/* step 1: the conditions that release a latched emergency brake (REQ-BR-006) */
#if defined(MUTANT_RESET_IGNORES_HANDLE)
#define RELEASE_OK (st && rs)
#elif defined(MUTANT_RELEASE_WHILE_MOVING)
#define RELEASE_OK (he && rs)
#else
#define RELEASE_OK RELEASE_ALL
#endif
/* step 2: the emergency pattern is exceeded (REQ-BR-001) */
#if defined(MUTANT_EMERGENCY_LATE)
#define OVERSPEED (vs > ve + 1)
#elif defined(MUTANT_EMERGENCY_AT_PATTERN)
#define OVERSPEED (vs >= ve)
#else
#define OVERSPEED (vs > ve)
#endif
#ifdef MUTANT_SERVICE_AT_PATTERN
#define OVER_7N (vs >= v7)
#else
#define OVER_7N (vs > v7)
#endif

/* The decision of one cycle, design note §4 (br::Supervisor::Step). */
inline decide() {
  if
  :: latched && !RELEASE_OK ->             /* 1. latched and not released: EB, stop here */
     level = L_EB; appr = 1; svc = L_NONE
  :: else ->
     latched = 0;                          /* 1. released (or not latched) */
     if
     :: OVERSPEED ->                       /* 2. emergency pattern exceeded: EB, latch */
#ifndef MUTANT_EMERGENCY_NOT_LATCHED
        latched = 1;
#endif
        level = L_EB; appr = 1; svc = L_NONE
     :: else ->
        if
        :: OVER_7N -> level = L_7N         /* 3. service pattern exceeded */
#ifndef MUTANT_MILD_LOWEST_FIRST
        :: else ->                         /* 4. mild brakes: the highest lead reached */
           if
           :: vs > v6 -> level = L_6N
           :: else ->
              if
              :: vs > v5 -> level = L_5N
              :: else ->
                 if
                 :: vs > v4 -> level = L_4N
                 :: else -> level = L_NONE
                 fi
              fi
           fi
#else
        :: else ->                         /* mutant: the lowest lead reached wins */
           if
           :: vs > v4 -> level = L_4N
           :: else ->
              if
              :: vs > v5 -> level = L_5N
              :: else ->
                 if
                 :: vs > v6 -> level = L_6N
                 :: else -> level = L_NONE
                 fi
              fi
           fi
#endif
        fi;
        if                                 /* 5. release only release_lead before the pattern */
#if defined(MUTANT_NO_RELEASE_LEAD)
        :: false -> skip
#elif defined(MUTANT_HOLD_WITHOUT_BRAKE)
        :: level == L_NONE && vs > vr -> level = L_4N
#else
        :: level == L_NONE && svc != L_NONE && vs > vr -> level = L_4N
#endif
        :: else -> skip
        fi;
        svc = level;
#ifdef MUTANT_INDICATION_BRAKE_ONLY
        appr = (level != L_NONE)
#else
        appr = (vs > vr || level != L_NONE)  /* 6. "pattern approaching" */
#endif
     fi
  fi
}

/* ---- properties, evaluated after every cycle ------------------------------------------- */
inline check() {
  /* REQ-BR-001 (with REQ-BR-006): EB iff the emergency pattern is exceeded or an earlier
   * EB is latched and not released in this cycle */
  if
  :: (level == L_EB) != (vs > ve || (was_latched && !RELEASE_ALL)) -> v_eb = 1
  :: else -> skip
  fi;
  /* REQ-BR-006: an EB is always latched; a latch is released only in a cycle with
   * standstill, handle in the emergency position and reset (so never while moving);
   * until then EB every cycle */
  if
  :: level == L_EB && !latched -> v_latch = 1
  :: was_latched && !latched && !(RELEASE_ALL && vs == 0) -> v_latch = 1
  :: was_latched && !RELEASE_ALL && level != L_EB -> v_latch = 1
  :: else -> skip
  fi;
  /* REQ-BR-002: without EB, 7N exactly while the service pattern is exceeded */
  if
  :: level != L_EB && (level == L_7N) != (vs > v7) -> v_service = 1
  :: else -> skip
  fi;
  /* REQ-BR-003 (levels): below the service pattern, 6N/5N exactly when the highest lead
   * reached is theirs, 4N at least when the 4N lead is the highest reached */
  if
  :: level != L_EB && vs <= v7 &&
     ((level == L_6N) != (vs > v6) ||
      (level == L_5N) != (vs <= v6 && vs > v5) ||
      (vs <= v6 && vs <= v5 && vs > v4 && level != L_4N)) -> v_mild = 1
  :: else -> skip
  fi;
  /* REQ-BR-003 (release): with no lead reached, an applied service brake is held (4N)
   * exactly while the train is within the release lead; nothing is applied otherwise */
  if
  :: level != L_EB && vs <= v7 && vs <= v6 && vs <= v5 && vs <= v4 &&
     (level == L_4N) != (prev != L_NONE && vs > vr) -> v_release = 1
  :: level != L_EB && vs <= v7 && vs <= v6 && vs <= v5 && vs <= v4 &&
     level != L_4N && level != L_NONE -> v_release = 1
  :: else -> skip
  fi;
  /* REQ-BR-003 (indication): "pattern approaching" within the release lead or while any
   * brake is applied */
  if
  :: appr != (vs > vr || level != L_NONE) -> v_ind = 1
  :: else -> skip
  fi
}

/* ---- coverage goals, from the state before the cycle, its inputs and its outputs -------- */
#define ON(c, k) if :: (c) -> GOAL(k) :: else -> skip fi
#define NO_LEAD (vs <= v7 && vs <= v6 && vs <= v5 && vs <= v4)
inline goals() {
  ON(was_latched && !st && he && rs, 0);
  ON(was_latched && st && !he && rs, 1);
  ON(was_latched && st && he && !rs, 2);
  ON(was_latched && RELEASE_ALL, 3);
  ON(was_latched && !st && !he && !rs && vs <= ve && vs <= v7, 4);
  ON(!was_latched && vs == ve + 1, 5);
  ON(!was_latched && vs == ve && vs > 0 && level != L_EB, 6);
  ON(level == L_7N && vs == v7 + 1, 7);
  ON(level != L_EB && vs == v7 && vs > v6, 8);
  ON(level == L_6N && vs == v6 + 1, 9);
  ON(level != L_EB && vs <= v7 && vs == v6 && vs > v5, 10);
  ON(level == L_5N && vs == v5 + 1, 11);
  ON(level != L_EB && vs <= v7 && vs <= v6 && vs == v5 && vs > v4, 12);
  ON(level == L_4N && vs == v4 + 1 && vs <= v5, 13);
  ON(level != L_EB && NO_LEAD && vs == v4 && prev == L_NONE && vs > vr, 14);
  ON(level == L_4N && NO_LEAD && prev == L_4N && vs == vr + 1, 15);
  ON(level == L_4N && NO_LEAD && prev >= L_5N && prev <= L_7N, 16);
  ON(level == L_NONE && prev != L_NONE && vs == vr, 17);
  ON(level == L_NONE && prev == L_NONE && !was_latched && vs == vr + 1, 18);
  ON(level == L_NONE && prev == L_NONE && !was_latched && vs == vr && vs > 0, 19);
  ON(level == L_EB && !was_latched && prev != L_NONE, 20);
  ON(level == L_EB && !was_latched && vs <= v7, 21);
  ON(level == L_7N && vs <= v6, 22);
  ON(was_latched && !RELEASE_ALL && vs > ve, 23)
}

inline clear_cycle() {
  vs = 0; ve = 0; v7 = 0; v6 = 0; v5 = 0; v4 = 0; vr = 0; st = 0; he = 0; rs = 0;
  level = 0; appr = 0; was_latched = 0; prev = 0
#ifdef REALISABLE
  ; must = 0; phase = 0
#endif
}

/* A pattern speed x, once printed, is kept only as its relation to v_s, all that the
 * decision, the properties and the goals read: more than one below v_s, one below, equal,
 * above. Its canonical value (v_s - 2, v_s - 1, v_s, v_s + 1; all within 0..VMAX) has the
 * same relation, so every comparison with v_s (>, >=, ==, > x + 1) gives the same result
 * on it as on the chosen value. This keeps the breadth-first search (which stores the
 * states inside the atomic cycle) small without losing any input. */
#define CANON(x) if :: x + 1 < vs -> x = vs - 2 :: x > vs -> x = vs + 1 :: else -> skip fi
#ifdef REALISABLE
/* REALISABLE: v_e exceeded makes v_7n's pick `must`; each service point then moves the phase
 * (exceeded, a run not exceeded, exceeded again), and phase 2 makes the rest `must` */
#define SHAPE(x, k) \
  if \
  :: k == 0 -> must = (vs > x) \
  :: k > 0 && phase == 0 && !(vs > x) -> phase = 1; must = 0 \
  :: k > 0 && phase == 1 && vs > x -> phase = 2; must = 1 \
  :: else -> must = (phase == 2) \
  fi
#else
#define SHAPE(x, k) skip
#endif
#define PICK(x, k) CHOOSE(x); d_step { printf("@IN p%d=%d\n", k, x); CANON(x); SHAPE(x, k) }

init {
  do
  :: atomic {
#ifdef WALK
       ncycles < MODEL_CYCLES -> ncycles++;
#endif
       CLEAR_GOALS;
       /* the environment: driver inputs, then speeds (standstill implies v_s = 0) */
       CHOOSE_BIT(st); CHOOSE_BIT(he); CHOOSE_BIT(rs);
       if
       :: st -> vs = 0
       :: else -> CHOOSE(vs)
       fi;
       printf("@IN cycle vs=%d st=%d he=%d rs=%d\n", vs, st, he, rs);
       /* the pattern speeds in the order of PatternSpeeds: p0 = v_e, p1 = v_7n, p2 = v_6n,
        * p3 = v_5n, p4 = v_4n, p5 = v_release */
       PICK(ve, 0); PICK(v7, 1); PICK(v6, 2); PICK(v5, 3); PICK(v4, 4); PICK(vr, 5);
       d_step {
         was_latched = latched; prev = svc;
         decide();
         printf("@OUT level=%d appr=%d latched=%d\n", level, appr, latched);
         check();
         goals();
         clear_cycle()
       }
     }
  od
}

// @property REQ_BR_001_emergency REQ-BR-001 REQ-BR-006 : the emergency brake is commanded in a cycle if and only if the supervised speed exceeds the emergency pattern or an emergency brake latched earlier is not released in that cycle (every value 0..MODEL_VMAX of the seven speeds, in every reachable state)
ltl REQ_BR_001_emergency { [] !v_eb }
// @property REQ_BR_006_latch REQ-BR-006 : a commanded emergency brake is latched; a latch is released only in a cycle with standstill, the brake handle in the emergency position and the reset switch operated (so never while moving, v_s = 0); until then the emergency brake is commanded every cycle
ltl REQ_BR_006_latch { [] !v_latch }
// @property REQ_BR_002_service REQ-BR-002 : without the emergency brake, 7N is commanded exactly while the supervised speed exceeds the service pattern
ltl REQ_BR_002_service { [] !v_service }
// @property REQ_BR_003_levels REQ-BR-003 : below the service pattern the mild brake of the highest lead reached is commanded (6N, 5N, 4N), whatever the order of the pattern speeds
ltl REQ_BR_003_levels { [] !v_mild }
// @property REQ_BR_003_release REQ-BR-003 : with no lead reached, an applied service brake is held (4N) exactly while the supervised speed exceeds the release-lead pattern speed, and no brake is applied otherwise
ltl REQ_BR_003_release { [] !v_release }
// @property REQ_BR_003_indication REQ-BR-003 : "pattern approaching" is shown exactly when the supervised speed exceeds the release-lead pattern speed or a brake is commanded
ltl REQ_BR_003_indication { [] !v_ind }

// @variant REALISABLE : the on-board unit's environment: only the relations between v_s and the pattern speeds the braking module's pattern calculator can give (v_e >= v_7n; the service points v_s exceeds are a prefix and a suffix); every property is verified there too, every goal searched again, and its vectors (br.unit.jsonl) are each replayed through the on-board unit
// @mutant MUTANT_RESET_IGNORES_HANDLE violates REQ_BR_006_latch : the latch is released at standstill with reset, whatever the brake handle (C++ FAULT_BR_RESET_IGNORES_HANDLE)
// @mutant MUTANT_RELEASE_WHILE_MOVING violates REQ_BR_006_latch : the latch is released with handle and reset without standstill (C++ FAULT_BR_RELEASE_WHILE_MOVING)
// @mutant MUTANT_NO_RELEASE_LEAD violates REQ_BR_003_release : an applied service brake is released as soon as no lead is reached (C++ FAULT_BR_NO_RELEASE_LEAD)
// @mutant MUTANT_EMERGENCY_LATE violates REQ_BR_001_emergency : the emergency brake only above the emergency pattern plus one (C++ FAULT_BR_EMERGENCY_LATE)
// @mutant MUTANT_EMERGENCY_NOT_LATCHED violates REQ_BR_006_latch : the emergency brake is commanded but not latched (C++ FAULT_BR_EMERGENCY_NOT_LATCHED)
// @mutant MUTANT_EMERGENCY_AT_PATTERN violates REQ_BR_001_emergency : the emergency brake already at the emergency pattern speed (>= instead of >)
// @mutant MUTANT_SERVICE_AT_PATTERN violates REQ_BR_002_service : 7N already at the service pattern speed (>= instead of >)
// @mutant MUTANT_MILD_LOWEST_FIRST violates REQ_BR_003_levels : the mild brakes are tried from 4N upwards, so the lowest lead reached wins
// @mutant MUTANT_HOLD_WITHOUT_BRAKE violates REQ_BR_003_release : 4N within the release lead although no brake was applied
// @mutant MUTANT_INDICATION_BRAKE_ONLY violates REQ_BR_003_indication : "pattern approaching" only while a brake is commanded

// ---- coverage goals (trap properties): every branch of the decision, each boundary ----
// @goal 0 REQ-BR-006 : latched EB held: standstill missing (handle and reset given, moving)
// @goal 1 REQ-BR-006 : latched EB held: brake handle not in the emergency position (standstill and reset given)
// @goal 2 REQ-BR-006 : latched EB held: reset missing (standstill and handle given)
// @goal 3 REQ-BR-006 : latched EB released: standstill, handle and reset in the same cycle
// @goal 4 REQ-BR-006 REQ-BR-001 : latched EB held although the speed is back under the emergency and service patterns
// @goal 5 REQ-BR-001 : boundary: EB at one above the emergency pattern (v_s = v_e + 1)
// @goal 6 REQ-BR-001 : boundary: no EB at the emergency pattern speed (v_s = v_e), train moving
// @goal 7 REQ-BR-002 : boundary: 7N at one above the service pattern (v_s = v_7n + 1)
// @goal 8 REQ-BR-002 REQ-BR-003 : boundary: no 7N at the service pattern speed (v_s = v_7n), 6N lead reached
// @goal 9 REQ-BR-003 : boundary: 6N at one above the 6N-lead speed (v_s = v_6n + 1)
// @goal 10 REQ-BR-003 : boundary: no 6N at the 6N-lead speed (v_s = v_6n), 5N lead reached
// @goal 11 REQ-BR-003 : boundary: 5N at one above the 5N-lead speed (v_s = v_5n + 1)
// @goal 12 REQ-BR-003 : boundary: no 5N at the 5N-lead speed (v_s = v_5n), 4N lead reached
// @goal 13 REQ-BR-003 : boundary: 4N at one above the 4N-lead speed (v_s = v_4n + 1)
// @goal 14 REQ-BR-003 : boundary: no brake at the 4N-lead speed (v_s = v_4n) with none applied, pattern approaching shown
// @goal 15 REQ-BR-003 : boundary: applied 4N held at one above the release-lead speed (v_s = v_release + 1)
// @goal 16 REQ-BR-003 : applied 5N-7N falls back to a held 4N within the release lead
// @goal 17 REQ-BR-003 : boundary: applied brake released at the release-lead speed (v_s = v_release)
// @goal 18 REQ-BR-003 : boundary: no brake applied, "pattern approaching" shown at one above the release-lead speed (v_s = v_release + 1)
// @goal 19 REQ-BR-003 : boundary: no brake, no indication at the release-lead speed (v_s = v_release), train moving
// @goal 20 REQ-BR-001 : EB while a service brake was applied (service level to EB)
// @goal 21 REQ-BR-001 : EB with the service pattern not exceeded (unordered pattern speeds)
// @goal 22 REQ-BR-002 REQ-BR-003 : 7N with the 6N lead not reached (unordered pattern speeds: the highest level wins)
// @goal 23 REQ-BR-006 REQ-BR-001 : latched EB held while the emergency pattern is still exceeded

#ifdef TRAPS
#include "br_goals.pml"
#endif
