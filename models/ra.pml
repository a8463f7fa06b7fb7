/*
 * railproof — re-adhesion state machine of the on-board odometry: slip/slide detection,
 * parallel compensation start points, re-adhesion judgement, maximum compensation time,
 * margin in force per odometry section, sensor failure and the stop demand (D1 chapter 3,
 * D1 §5.2; spec/design/ra.md §5; C++: ra::ReadhesionMachine::Step,
 * cpp/runtime/ra/src/readhesion_machine.cpp).
 *
 * What is modelled. One 100 ms odometry cycle of the state machine and the state it keeps
 * between cycles: the mode (TG odometry, compensating, stopped), the stop reason, the
 * deviation counter, up to two candidates (active, age in cycles, confirmation counter),
 * the episode limits (maximum compensation time t_max in force and margin in force), the
 * stop demand, the position validity and the start-up state (design note §5a: whether the
 * TG history is trusted, and the run of standstill cycles towards the warm-up). The signal
 * processing (design note §3) is abstracted into the predicates of design note §4, chosen
 * by the environment every cycle: deviation, speed_agrees[0..1], imu_ok, tg_ok, balise,
 * tg_moving (a TG pulse in the cycle), the odometry section under the train and the age of
 * the primary start point (MODEL_START_AGE + 0..MODEL_SEARCH_EXTRA, the look-back plus the
 * start-point search; read only in a detection cycle).
 *
 * Start-up (REQ-RA-015). The machine starts stopped (reason START_UP): the odometry's
 * averages and windows are empty, so a slip could not be detected. The TG history becomes
 * trusted after MODEL_WARMUP consecutive cycles with healthy sensors and no TG pulse (a
 * warm-up at standstill, so every average starts from a true zero speed); any stop (a
 * timeout or a sensor failure, after which the history restarts) withdraws the trust. A
 * start-up without motion ends with the warm-up (the position given at start-up holds);
 * a TG pulse before the trust makes it a start in motion (reason START_IN_MOTION), which,
 * like every other stop, ends only with a balise read once the history is trusted. While a
 * stop waits with the history trusted, MODEL_CONFIRM deviations in a row withdraw the trust
 * (a TG wheel locked through the "standstill" that rolls again shows as such a run). Model ticks
 * are cycles and the abstract margins are fed to the C++ as mm unchanged, which is exact:
 * the machine only compares ages with t_max and takes minima and maxima of the limits.
 *
 * Sections. Three kinds, any of them under the train in any cycle: a normal section
 * (t_max MODEL_TMAX_LONG, margin MODEL_MARGIN_LONG), a steep section that keeps the normal
 * time (MODEL_TMAX_LONG, the largest margin MODEL_MARGIN_STEEP) and a tight section with a
 * shortened time (MODEL_TMAX_SHORT, the smallest margin MODEL_MARGIN_SHORT). So an episode
 * can meet a larger margin, a shorter time, or both, in any order.
 *
 * Environment. Every cycle the section, imu_ok, tg_ok and balise are chosen freely. An
 * input that the cycle of the design note does not read in the current situation is not
 * varied in the exhaustive searches (verification and trap goals), it is fixed to 0 (or
 * the look-back age): the deviation in the stopped state or with a failed sensor, the
 * speed agreement outside compensation, the start-point age outside a possible detection
 * cycle (TG odometry, healthy sensors, deviation). Every value of every input that is
 * read is among the choices in every reachable state. The random walks (WALK) choose every
 * input every cycle, so the vectors also show that the C++ ignores the others; their
 * choices are weighted (CHOOSE_OK and the others below) so that a walk of MODEL_CYCLES
 * cycles reaches detections, compensation, re-adhesion and timeouts.
 *
 * The cycle runs in the order of design note §5 (cycle() below, step numbers as there).
 * The properties are evaluated by check() after every cycle on the state before it, the
 * inputs, the state after it and ghost variables that follow the inputs only, never the
 * machine's counters: g_run (consecutive deviations in TG odometry with healthy sensors),
 * g_sage and g_since (start-point age at detection and cycles since it: a candidate's true
 * age), g_seen (the section kinds under the train in every cycle of the episode), g_hist
 * (per candidate, the last MODEL_CONFIRM cycles' "no deviation and speed agrees" bits).
 * Violations are latched in v_* bits; each LTL property says one of them never becomes 1.
 * Inputs, outputs and scratch values are cleared at the end of the cycle so that the
 * stored state is the machine's state and the ghosts only; the search is exhaustive over
 * unbounded runs.
 *
 * Configurations (-D): default = two parallel start points (verification and trap
 * goals; TRAPS adds the goal flags); ONE_START = one start point (a boundary variant:
 * every property is verified in it too, and it supplies the vectors of
 * ra.one_start.jsonl); WALK stops after MODEL_CYCLES cycles (random-walk vectors).
 * UNIT (with WALK; random walks only, ra.unit.jsonl) is the on-board unit's environment,
 * the one its external interface (TG pulses and IMU samples) can give the machine: the
 * unit's times (MODEL_UNIT_*: the look-back and search of the start point, the spacing, the
 * warm-up, the sections' times, all in 100 ms cycles) and only input sequences a sensor
 * stream can produce (unit_inputs() below: one section under the standing train; the start
 * point's age one the search can find in the history since the last restart; no TG motion
 * in the first cycle of a history; the primary agrees only if the older, more tolerant
 * candidate does, and exactly when the two start points are one, the oldest usable entry; one
 * detection per walk). Its counters run to 100 and more, so it is not
 * searched exhaustively: the properties are those verified in the default configuration.
 *
 * Annotations read by testgen: see models/tg.pml.
 */
#include "ra_params.pml"
#ifdef UNIT
#ifndef WALK
#error "UNIT is an environment for random walks (define WALK too)"
#endif
#undef MODEL_START_AGE
#undef MODEL_SEARCH_EXTRA
#undef MODEL_SPACING
#undef MODEL_TMAX_LONG
#undef MODEL_TMAX_SHORT
#undef MODEL_WARMUP
#undef MODEL_CYCLES
#define MODEL_START_AGE MODEL_UNIT_START_AGE
#define MODEL_SEARCH_EXTRA MODEL_UNIT_SEARCH_EXTRA
#define MODEL_SPACING MODEL_UNIT_SPACING
#define MODEL_TMAX_LONG MODEL_UNIT_TMAX_LONG
#define MODEL_TMAX_SHORT MODEL_UNIT_TMAX_SHORT
#define MODEL_WARMUP MODEL_UNIT_WARMUP
#define MODEL_CYCLES MODEL_UNIT_CYCLES
#endif

#define CONFIRM MODEL_CONFIRM
#define SPACING MODEL_SPACING
#if MODEL_CONFIRM < 2 || MODEL_CONFIRM > 7
#error "the ghost history g_hist holds up to 7 cycles and the goals need MODEL_CONFIRM >= 2"
#endif
#if MODEL_TMAX_SHORT > MODEL_TMAX_LONG || MODEL_MARGIN_STEEP < MODEL_MARGIN_LONG
#error "section kinds: the tight section has the shorter time, the steep one the larger margin"
#endif
#ifdef ONE_START
#define NSP 1
#else
#define NSP 2
#endif
#define HMASK ((1 << CONFIRM) - 1)

/* modes and stop reasons (ra::Mode, ra::StopReason, in order) */
#define M_TG 0
#define M_COMP 1
#define M_STOP 2
#define R_NONE 0
#define R_MAXT 1
#define R_IMU 2
#define R_TG 3
#define R_START 4
#define R_MOVED 5
#define NONE 255
/* section kinds: limits (T_s cycles, M_s margin units) */
#define S_LONG 0
#define S_STEEP 1
#define S_SHORT 2
#define SEC_T(k) ((k) == S_SHORT -> MODEL_TMAX_SHORT : MODEL_TMAX_LONG)
#define SEC_M(k) ((k) == S_LONG -> MODEL_MARGIN_LONG : ((k) == S_STEEP -> MODEL_MARGIN_STEEP : MODEL_MARGIN_SHORT))

/* ---- machine state (ra::MachineState) ------------------------------------------- */
#ifndef MUTANT_NO_WARMUP
byte mode = M_STOP, reason = R_START, dcount;
#else
byte mode = M_TG, reason = R_NONE, dcount;
#endif
bit act[2];                /* candidates: active, age (cycles), confirmation counter */
byte age[2], conf[2];
byte tmax, margin;         /* maximum compensation time and margin in force */
#ifndef MUTANT_NO_WARMUP
bit stop = 1, valid;
bit trust;                 /* the TG history is trusted (a warm-up at standstill since the last stop) */
#else
bit stop, valid = 1;
bit trust = 1;
#endif
byte rest;                 /* consecutive healthy cycles without a TG pulse while not trusted */
/* ---- events of the cycle (cleared at its end) ------------------------------------------ */
bit detected, breset;
byte adopted = NONE;
/* ---- inputs of the cycle (cleared at its end) ------------------------------------------ */
bit dev, sa[2], imu, tg, bal, mv;
byte sec, sage;
/* ---- scratch: the state at the start of the cycle, loop index (cleared at its end) ----- */
byte was_mode, was_reason, was_dcount, was_tmax, was_margin, was_rest, c;
bit was_trust;
bit was_act[2];
byte was_conf[2];
#ifdef MUTANT_MARGIN_LATE
byte late_m;               /* mutant only: the previous cycle's section margin */
#endif
#ifdef WALK
short ncycles;
#endif
#ifdef UNIT
/* the unit's environment: the history index of the cycle (accepted cycles since the last
 * restart, capped), the section under the train, whether a detection has happened, scratch */
#define AGE_TOP (MODEL_START_AGE + MODEL_SEARCH_EXTRA)
#define HL_CAP (MODEL_WARMUP + CONFIRM + AGE_TOP)
byte hl, usec, u_r;
bit eps, u_same, u_b;
#endif
/* ---- ghost: follows the inputs only ---------------------------------------------------- */
byte g_run;                /* consecutive deviations in TG odometry with healthy sensors */
bit g_ep;                  /* an episode (detection ... end of compensation) is running */
byte g_sage, g_since;      /* start-point age at detection, cycles since the detection */
byte g_seen;               /* bit k: section kind k under the train in a cycle of the episode */
byte g_hist[2];            /* per candidate: the last CONFIRM "no deviation and speed agrees" bits */
byte g_mint, g_mmax;       /* scratch: shortest time and largest margin of g_seen */
byte g_calm;               /* consecutive healthy cycles without a TG pulse since the last stop */
byte g_srun;               /* consecutive deviations while stopped with the history trusted */
bit g_trust = 0;           /* g_calm reached MODEL_WARMUP since the last stop (and start-up) */
bit g_lost;                /* the start-up position is no longer known: a TG pulse or a sensor
                              failure before the start-up stop ended */
bit g_started;             /* the start-up stop has ended once */
/* ---- ghost: latched property violations ----------------------------------------------- */
bit v_detect, v_start, v_readh, v_timeout, v_stopped, v_limits, v_parallel, v_balise, v_sensor;
bit v_startup;
#ifdef TRAPS
bit g[56];
byte h_i;
/* goal flags mark the goals reached in the last cycle only (cleared at the start of each
 * cycle), so that they do not multiply the states of the breadth-first trap searches */
#define GOAL(k) g[k] = 1
#define CLEAR_GOALS d_step { for (h_i : 0 .. 55) { g[h_i] = 0 }; h_i = 0 }
#else
#define CLEAR_GOALS skip
#define GOAL(k) skip
#endif

#define HEALTHY (imu && tg)
/* a candidate's true age (ghost) and whether it is within every t_max of the episode */
#define TRUE_AGE(k) (g_sage + (k) * SPACING + g_since)
#define ALIVE(k) ((k) < NSP && g_ep && TRUE_AGE(k) <= g_mint)
#define FULL(k) ((g_hist[k] & HMASK) == HMASK)

#define CHOOSE_BIT(b) if :: b = 0 :: b = 1 fi
#define CHOOSE_SEC(s) if :: s = S_LONG :: s = S_STEEP :: s = S_SHORT fi
#ifdef UNIT
/* the start points the unit's search can give at history index hl (spec/design/ra.md §7):
 * one found at MODEL_START_AGE .. min(AGE_TOP, hl - MODEL_WARMUP - CONFIRM) (its jerk
 * conditions need CONFIRM entries after the first MODEL_WARMUP), or the search's fallback,
 * the oldest usable point, min(AGE_TOP, hl - MODEL_WARMUP); an offset drawn from 6 bits */
#define CHOOSE_AGE(a) \
  u_r = 0; \
  CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; \
  CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; \
  CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; CHOOSE_BIT(u_b); u_r = u_r * 2 + u_b; \
  if \
  :: hl >= MODEL_WARMUP + CONFIRM + MODEL_START_AGE -> \
     a = MODEL_START_AGE + u_r % ((hl - MODEL_WARMUP - CONFIRM < AGE_TOP -> hl - MODEL_WARMUP - CONFIRM : AGE_TOP) \
                                  - MODEL_START_AGE + 1) \
  :: hl >= MODEL_WARMUP -> a = (hl - MODEL_WARMUP < AGE_TOP -> hl - MODEL_WARMUP : AGE_TOP) \
  :: else -> a = 0 \
  fi; \
  u_r = 0; u_b = 0
#else
#define CHOOSE_AGE(a) \
  if \
  :: a = MODEL_START_AGE \
  :: (MODEL_SEARCH_EXTRA >= 1) -> a = MODEL_START_AGE + 1 \
  :: (MODEL_SEARCH_EXTRA >= 2) -> a = MODEL_START_AGE + 2 \
  :: (MODEL_SEARCH_EXTRA >= 3) -> a = MODEL_START_AGE + 3 \
  fi
#if MODEL_SEARCH_EXTRA > 3
#error "CHOOSE_AGE enumerates up to MODEL_SEARCH_EXTRA = 3: extend it"
#endif
#endif
#ifdef WALK
/* random walks: a sensor fails in 1 of 32 cycles, a balise is read in 1 of 4; a deviation
 * in 3 of 4 cycles outside compensation and in 1 of 4 while compensating, the speed
 * agreement in 3 of 4, so that a walk reaches detections, re-adhesion and timeouts */
#define CHOOSE_OK(b) \
  if \
  :: b = 0 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 \
  :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 \
  :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 \
  :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 :: b = 1 \
  fi
#define CHOOSE_BALISE(b) if :: b = 1 :: b = 0 :: b = 0 :: b = 0 fi
#define CHOOSE_LIKELY(b) if :: b = 1 :: b = 1 :: b = 1 :: b = 0 fi
#define CHOOSE_UNLIKELY(b) if :: b = 1 :: b = 0 :: b = 0 :: b = 0 fi
/* motion: rare before the trust (the warm-up at standstill completes in most walks) */
#define CHOOSE_MOTION(b) if :: trust -> CHOOSE_LIKELY(b) :: else -> if :: b = 1 :: b = 0 :: b = 0 :: b = 0 :: b = 0 :: b = 0 :: b = 0 :: b = 0 fi fi
#else
#define CHOOSE_OK(b) CHOOSE_BIT(b)
#define CHOOSE_BALISE(b) CHOOSE_BIT(b)
#endif

#ifdef UNIT
/* The inputs of a cycle in the unit's environment (random walks). A sensor fails in about 1
 * of 512 cycles each (a failure restarts the history and the 40-cycle warm-up), a TG pulse
 * before the trust comes in 1 of 32 cycles and never in the first cycle of a history (the
 * odometry has no count to compare there); a deviation in 1 of 4 cycles, the agreement in 1
 * of 2. The train stands on one section (chosen in the first cycle). The primary candidate
 * agrees only when the second does: both integrate the same IMU stream from start points
 * where it agrees with the TG, so they have one speed, and the second, 25 cycles older,
 * allows the larger difference (design note §7); where the primary's start point is the
 * oldest usable history entry, the second is clamped to it and the two agree alike. One
 * detection per walk: the start-point search of a second one would look into the history the
 * first compensation replaced. */
/* a sensor fails in 1 of 32 x 4 x 4 = 512 cycles */
#define CHOOSE_HEALTH(b) \
  CHOOSE_OK(b); if :: !b -> CHOOSE_LIKELY(b); if :: !b -> CHOOSE_LIKELY(b) :: else -> skip fi :: else -> skip fi
inline unit_inputs() {
  if :: ncycles == 1 -> CHOOSE_SEC(usec) :: else -> skip fi;
  sec = usec;
  CHOOSE_HEALTH(imu); CHOOSE_HEALTH(tg);
  CHOOSE_BALISE(bal);
  if
  :: mode == M_TG && eps && dcount == CONFIRM - 1 -> dev = 0
  :: else -> CHOOSE_UNLIKELY(dev)
  fi;
  if
  :: !trust && hl > 0 -> CHOOSE_OK(u_b); mv = 1 - u_b; u_b = 0
  :: else -> mv = 0
  fi;
  CHOOSE_BIT(sa[0]);
  if
  :: u_same -> sa[1] = sa[0]
  :: !u_same && sa[0] -> sa[1] = 1
  :: else -> CHOOSE_BIT(sa[1])
  fi;
  CHOOSE_AGE(sage)
}
#endif

/* ---- the cycle, design note §5 --------------------------------------------------------- */
inline discard() {
  act[0] = 0; age[0] = 0; conf[0] = 0;
  act[1] = 0; age[1] = 0; conf[1] = 0
}

/* step 6: the safe reaction of the timeout */
inline untrust() {
#ifndef MUTANT_TRUST_KEPT_ON_STOP
  trust = 0; rest = 0
#else
  skip
#endif
}

inline stop_timeout() {
  discard();
  untrust();
  mode = M_STOP; reason = R_MAXT; stop = 1;
#ifndef MUTANT_STOP_POSITION_VALID
  valid = 0
#else
  skip
#endif
}

#if defined(MUTANT_DETECT_EARLY)
#define DETECT_AT (CONFIRM - 1)
#elif defined(MUTANT_DETECT_LATE)
#define DETECT_AT (CONFIRM + 1)
#else
#define DETECT_AT CONFIRM
#endif
#if defined(MUTANT_START_AT_DETECTION)
#define START_OF(k) ((k) * SPACING)
#elif defined(MUTANT_NO_SPACING)
#define START_OF(k) sage
#else
#define START_OF(k) (sage + (k) * SPACING)
#endif
#ifdef MUTANT_TIMEOUT_OFF_BY_ONE
#define AGE_LIMIT (tmax + 1)
#else
#define AGE_LIMIT tmax
#endif
#ifdef MUTANT_CONFIRM_TWO
#define NEEDED (CONFIRM - 1)
#else
#define NEEDED CONFIRM
#endif
#if defined(MUTANT_SPEED_IGNORED)
#define BOTH(k) (!dev)
#elif defined(MUTANT_DEVIATION_IGNORED)
#define BOTH(k) (sa[k])
#else
#define BOTH(k) (!dev && sa[k])
#endif
#ifdef MUTANT_TG_FAILURE_IGNORED
#define FAILED (!imu)
#else
#define FAILED (!imu || !tg)
#endif

inline cycle() {
  /* 1. section limits: an episode never relaxes them */
#if defined(MUTANT_EPISODE_RELAXES)
  tmax = SEC_T(sec); margin = SEC_M(sec);
#elif defined(MUTANT_MARGIN_LATE)
  if
  :: was_mode == M_COMP ->
     if :: SEC_T(sec) < tmax -> tmax = SEC_T(sec) :: else -> skip fi;
     if :: late_m > margin -> margin = late_m :: else -> skip fi
  :: else -> tmax = SEC_T(sec); margin = late_m
  fi;
  late_m = SEC_M(sec);
#else
  if
  :: was_mode == M_COMP ->
     if :: SEC_T(sec) < tmax -> tmax = SEC_T(sec) :: else -> skip fi;
     if :: SEC_M(sec) > margin -> margin = SEC_M(sec) :: else -> skip fi
  :: else -> tmax = SEC_T(sec); margin = SEC_M(sec)
  fi;
#endif
  if
  :: FAILED ->                          /* 2. sensor failure: stop, IMU checked first */
     dcount = 0;
#ifndef MUTANT_FAILURE_KEEPS_CANDIDATES
     discard();
#endif
     mode = M_STOP; stop = 1; valid = 0;
     reason = (!imu -> R_IMU : R_TG);
     trust = 0; rest = 0                /* the history restarts after a rejected cycle */
  :: else ->
     /* 2a. the warm-up at standstill (REQ-RA-015): healthy cycles without a TG pulse */
     if
     :: !trust ->
        if
#ifndef MUTANT_WARMUP_COUNTS_MOTION
        :: mv -> rest = 0;
           if :: reason == R_START -> reason = R_MOVED :: else -> skip fi
#endif
        :: else -> if :: rest < MODEL_WARMUP -> rest++ :: else -> skip fi
        fi;
        if :: rest >= MODEL_WARMUP -> trust = 1; rest = 0 :: else -> skip fi
     :: else -> skip
     fi;
     if
     :: mode == M_STOP ->               /* 3. held until trusted and a balise (start-up: trusted) */
        stop = 1; valid = 0;
        if                              /* a deviation run while waiting withdraws the trust */
        :: was_trust ->
           if :: dev -> dcount++ :: else -> dcount = 0 fi;
#ifndef MUTANT_TRUST_KEPT_ON_DEVIATION
           if :: dcount >= CONFIRM -> trust = 0; rest = 0; dcount = 0 :: else -> skip fi
#else
           skip
#endif
        :: else -> skip
        fi;
        if
#if defined(MUTANT_RELEASED_WITHOUT_BALISE)
        :: trust ->
#elif defined(MUTANT_BALISE_WITHOUT_WARMUP)
        :: bal || (trust && reason == R_START) ->
#elif defined(MUTANT_START_MOVED_IGNORED)
        :: trust && (bal || reason == R_START || reason == R_MOVED) ->
#else
        :: trust && (bal || reason == R_START) ->
#endif
           mode = M_TG; reason = R_NONE; stop = 0; valid = 1; dcount = 0; breset = bal
        :: else -> skip
        fi
     :: mode == M_TG ->                 /* 4. detection */
        if :: dev -> dcount++ :: else -> dcount = 0 fi;
#ifndef MUTANT_BALISE_IGNORED_IN_TG
        if :: bal -> breset = 1 :: else -> skip fi;
#endif
        if
        :: dcount == DETECT_AT ->
           dcount = 0; detected = 1; mode = M_COMP;
           act[0] = 1; age[0] = START_OF(0); conf[0] = 0;
           if
           :: NSP == 2 -> act[1] = 1; age[1] = START_OF(1); conf[1] = 0
           :: else -> skip
           fi;
           c = 0;                       /* a start point older than t_max: discarded at once */
           do
           :: c < 2 ->
              if
              :: act[c] && age[c] > tmax -> act[c] = 0; age[c] = 0; conf[c] = 0
              :: else -> skip
              fi;
              c++
           :: else -> break
           od;
           if :: !act[0] && !act[1] -> stop_timeout() :: else -> skip fi
        :: else -> skip
        fi
     :: mode == M_COMP ->               /* 5. age, timeout, re-adhesion judgement */
        c = 0;
        do
        :: c < 2 ->
           if
           :: act[c] ->
              age[c]++;
              if
              :: age[c] > AGE_LIMIT -> act[c] = 0; age[c] = 0; conf[c] = 0
              :: else ->
                 if
                 :: BOTH(c) -> if :: conf[c] < NEEDED -> conf[c]++ :: else -> skip fi
#ifdef MUTANT_CONFIRM_NOT_RESET
                 :: else -> skip
#else
                 :: else -> conf[c] = 0
#endif
                 fi
              fi
           :: else -> skip
           fi;
           c++
        :: else -> break
        od;
        /* the lowest index that completed its confirmation is adopted */
        if
#ifdef MUTANT_LAST_CANDIDATE_WINS
        :: act[1] && conf[1] >= NEEDED -> adopted = 1
#endif
        :: act[0] && conf[0] >= NEEDED -> adopted = 0
        :: else ->
           if
           :: act[1] && conf[1] >= NEEDED -> adopted = 1
           :: else -> skip
           fi
        fi;
        if
        :: adopted != NONE ->
#ifdef MUTANT_OTHER_KEPT
           act[adopted] = 0; age[adopted] = 0; conf[adopted] = 0;
#else
           discard();
#endif
           mode = M_TG; dcount = 0
        :: else ->
           if :: !act[0] && !act[1] -> stop_timeout() :: else -> skip fi   /* 6. */
        fi
     fi
  fi
}

/* ---- ghost update from the inputs, then the properties --------------------------------- */
inline ghost() {
  /* start-up (REQ-RA-015): the start-up position is lost by a TG pulse before the trust or
   * by a sensor failure before the start-up stop ended; the trust follows the healthy
   * cycles without a TG pulse since the last stop (or the start) */
  if :: !g_started && (!HEALTHY || (mv && !g_trust)) -> g_lost = 1 :: else -> skip fi;
  if
  :: was_mode == M_STOP && HEALTHY && g_trust && dev -> g_srun++
  :: else -> g_srun = 0
  fi;
  if
  :: !HEALTHY || (mode == M_STOP && was_mode != M_STOP) || g_srun >= CONFIRM -> g_calm = 0; g_trust = 0; g_srun = 0
  :: g_trust -> skip
  :: mv -> g_calm = 0
  :: else ->
     g_calm++;
     if :: g_calm >= MODEL_WARMUP -> g_trust = 1; g_calm = 0 :: else -> skip fi
  fi;
  if :: was_mode == M_STOP && mode != M_STOP -> g_started = 1 :: else -> skip fi;
  /* sections of the episode (the detection cycle and every compensating cycle after it) */
  g_seen = (was_mode == M_COMP -> g_seen : 0) | (1 << sec);
  g_mint = 255; g_mmax = 0;
  c = 0;
  do
  :: c < 3 ->
     if
     :: (g_seen >> c) & 1 ->
        if :: SEC_T(c) < g_mint -> g_mint = SEC_T(c) :: else -> skip fi;
        if :: SEC_M(c) > g_mmax -> g_mmax = SEC_M(c) :: else -> skip fi
     :: else -> skip
     fi;
     c++
  :: else -> break
  od;
  /* consecutive deviations in TG odometry with healthy sensors */
  if
  :: was_mode == M_TG && HEALTHY && dev -> g_run++
  :: else -> g_run = 0
  fi;
  /* the episode: begins when the deviations reach CONFIRM, then one cycle per cycle */
  if
  :: was_mode == M_TG && g_run == CONFIRM ->
     g_ep = 1; g_sage = sage; g_since = 0; g_hist[0] = 0; g_hist[1] = 0
  :: was_mode == M_COMP && HEALTHY && g_ep ->
     g_since++;
     g_hist[0] = ((g_hist[0] << 1) | (!dev && sa[0])) & HMASK;
     g_hist[1] = ((g_hist[1] << 1) | (!dev && sa[1])) & HMASK
  :: else -> g_ep = 0
  fi;
  if :: !ALIVE(0) -> g_hist[0] = 0 :: else -> skip fi;
  if :: !ALIVE(1) -> g_hist[1] = 0 :: else -> skip fi
}

inline check() {
  /* REQ-RA-003: in TG odometry with healthy sensors, the mode leaves TG exactly when
   * CONFIRM consecutive deviations have been seen; the detection event exactly then;
   * compensation only in an episode begun so */
  if
  :: was_mode == M_TG && HEALTHY && ((mode != M_TG) != (g_run == CONFIRM)) -> v_detect = 1
  :: detected != (was_mode == M_TG && g_run == CONFIRM) -> v_detect = 1
  :: mode == M_COMP && !g_ep -> v_detect = 1
  :: else -> skip
  fi;
  /* REQ-RA-004 (REQ-RA-010): every candidate compensates from its start point: its age is
   * the start-point age found at detection (the second start point MODEL_SPACING older)
   * plus the cycles since the detection */
  if
  :: mode == M_COMP && act[0] && age[0] != TRUE_AGE(0) -> v_start = 1
  :: mode == M_COMP && act[1] && age[1] != TRUE_AGE(1) -> v_start = 1
  :: else -> skip
  fi;
  /* REQ-RA-006: a return to TG odometry from compensation only by an adoption, and the
   * adopted candidate had no deviation and speed agreement in each of the last CONFIRM
   * cycles since the detection */
  if
  :: was_mode == M_COMP && mode == M_TG && adopted == NONE -> v_readh = 1
  :: adopted != NONE && !(adopted < NSP && FULL(adopted)) -> v_readh = 1
  :: else -> skip
  fi;
  /* REQ-RA-007: while compensating, exactly the candidates whose true age is within every
   * t_max of the episode are active, never older than t_max in force; when none is left
   * (and none adopted), the stop demand and the invalid position in that cycle */
  if
  :: mode == M_COMP && (act[0] != ALIVE(0) || act[1] != ALIVE(1)) -> v_timeout = 1
  :: mode == M_COMP && act[0] && age[0] > tmax -> v_timeout = 1
  :: mode == M_COMP && act[1] && age[1] > tmax -> v_timeout = 1
  :: g_ep && HEALTHY && !ALIVE(0) && !ALIVE(1) &&
     !(mode == M_STOP && reason == R_MAXT && stop && !valid && adopted == NONE) -> v_timeout = 1
  :: else -> skip
  fi;
  /* REQ-RA-007: stop demand and invalid position exactly in the stopped state (with a
   * reason), held until a balise read with healthy sensors and the history trusted, which
   * re-establishes TG odometry (the start-up stop: the warm-up, REQ-RA-015); a stop held
   * with healthy sensors keeps its reason, but for the start-up that saw motion */
  if
  :: stop != (mode == M_STOP) || valid != (mode != M_STOP) -> v_stopped = 1
  :: (mode == M_STOP) != (reason != R_NONE) -> v_stopped = 1
  :: was_mode == M_STOP && mode != M_STOP && !(HEALTHY && mode == M_TG && (bal || was_reason == R_START)) -> v_stopped = 1
  :: was_mode == M_STOP && mode == M_STOP && HEALTHY && reason != was_reason &&
     !(was_reason == R_START && reason == R_MOVED && mv) -> v_stopped = 1
  :: was_mode == M_STOP && HEALTHY && bal && g_trust && mode != M_TG -> v_stopped = 1
  :: else -> skip
  fi;
  /* REQ-RA-015: a valid position only with the history trusted, i.e. after a warm-up of
   * MODEL_WARMUP healthy cycles without a TG pulse since the last stop (and no run of
   * MODEL_CONFIRM deviations while stopped since); a stop ends without
   * a balise only at start-up, with no TG pulse and no sensor failure before the trust,
   * and then as soon as the warm-up is complete */
  if
  :: valid && !g_trust -> v_startup = 1
  :: trust != g_trust -> v_startup = 1
  :: was_mode == M_STOP && mode == M_TG && !bal && (g_lost || was_reason != R_START) -> v_startup = 1
  :: mode == M_STOP && reason == R_START && g_lost -> v_startup = 1
  :: was_mode == M_STOP && was_reason == R_START && HEALTHY && g_trust && !g_lost && mode != M_TG -> v_startup = 1
  :: else -> skip
  fi;
  /* REQ-RA-009: margin in force >= the margin and t_max in force <= the time of every
   * section under the train in this cycle and in every cycle of the episode */
  if
  :: margin < g_mmax || tmax > g_mint -> v_limits = 1
  :: else -> skip
  fi;
  /* REQ-RA-010: the adopted candidate is the lowest index that completed its confirmation
   * (within t_max), in the first cycle any did; nothing stays active after the adoption */
  if
  :: was_mode == M_COMP && HEALTHY && g_ep &&
     adopted != (ALIVE(0) && FULL(0) -> 0 : (ALIVE(1) && FULL(1) -> 1 : NONE)) -> v_parallel = 1
  :: adopted != NONE && (act[0] || act[1] || mode != M_TG) -> v_parallel = 1
  :: else -> skip
  fi;
  /* REQ-RA-012: a balise in TG odometry (and the one that ends a stop) resets the
   * accumulated error; no reset without a balise, none while compensating */
  if
  :: (was_mode == M_TG || (was_mode == M_STOP && mode == M_TG)) && HEALTHY && bal && !breset -> v_balise = 1
  :: breset && !(bal && HEALTHY && was_mode != M_COMP) -> v_balise = 1
  :: else -> skip
  fi;
  /* REQ-RA-013: a sensor failure gives in the same cycle the stopped state with its
   * reason (IMU first), the stop demand, the invalid position, no candidate, no adoption */
  if
  :: !HEALTHY && !(mode == M_STOP && stop && !valid && !act[0] && !act[1] && adopted == NONE &&
                   reason == (!imu -> R_IMU : R_TG)) -> v_sensor = 1
  :: else -> skip
  fi
}

/* ---- coverage goals, from the state before the cycle, its inputs and outputs ----------- */
#define ON(cond, k) if :: (cond) -> GOAL(k) :: else -> skip fi
#define COMP_CYCLE (was_mode == M_COMP && HEALTHY)
inline goals() {
  ON(detected && act[0] && act[1], 0);
  ON(was_mode == M_TG && HEALTHY && was_dcount == CONFIRM - 1 && !dev && mode == M_TG, 1);
  ON(detected && breset, 2);
  ON(detected && act[0] && age[0] == MODEL_START_AGE + MODEL_SEARCH_EXTRA, 3);
  ON(adopted == 0 && g_since == CONFIRM, 4);
  ON(COMP_CYCLE && was_act[0] && was_conf[0] == CONFIRM - 1 && dev && act[0] && conf[0] == 0, 5);
  ON(COMP_CYCLE && was_act[0] && was_conf[0] > 0 && !dev && !sa[0] && act[0] && conf[0] == 0, 6);
  ON(adopted != NONE && g_since > CONFIRM, 7);
  ON(adopted == 1 && ALIVE(0), 8);
  ON(adopted == 1 && ALIVE(0) && (g_hist[0] & (HMASK >> 1)) == (HMASK >> 1), 9);
  ON(adopted == 0 && ALIVE(1) && FULL(1), 10);
  ON(adopted == 0 && was_act[1] && !ALIVE(1), 11);
  ON(mode == M_COMP && act[0] && age[0] == tmax, 12);
  ON(COMP_CYCLE && mode == M_STOP && reason == R_MAXT && TRUE_AGE(0) == tmax + 1, 13);
  ON(COMP_CYCLE && was_act[1] && !act[1] && act[0] && mode == M_COMP, 14);
  ON(COMP_CYCLE && mode == M_STOP && reason == R_MAXT && tmax < was_tmax, 15);
  ON(COMP_CYCLE && mode == M_COMP && tmax < was_tmax, 16);
  ON(COMP_CYCLE && margin > was_margin, 17);
  ON(COMP_CYCLE && mode == M_COMP && margin > SEC_M(sec), 18);
  ON(COMP_CYCLE && mode == M_COMP && tmax < SEC_T(sec), 19);
  ON(was_mode == M_TG && mode == M_TG && margin < was_margin, 20);
  ON(was_mode == M_TG && !imu, 21);
  ON(was_mode == M_COMP && !imu, 22);
  ON(was_mode == M_STOP && was_reason == R_MAXT && !imu, 23);
  ON(was_mode == M_TG && imu && !tg, 24);
  ON(was_mode == M_COMP && imu && !tg, 25);
  ON(was_mode == M_STOP && imu && !tg, 26);
  ON(!imu && !tg, 27);
  ON(was_mode == M_TG && HEALTHY && bal && mode == M_TG, 28);
  ON(COMP_CYCLE && bal && mode == M_COMP, 29);
  ON(was_mode == M_STOP && was_reason == R_MAXT && mode == M_TG, 30);
  ON(was_mode == M_STOP && (was_reason == R_IMU || was_reason == R_TG) && mode == M_TG, 31);
  ON(was_mode == M_STOP && bal && !HEALTHY, 32);
  ON(was_mode == M_STOP && HEALTHY && !bal, 33);
  ON(detected && mode == M_COMP && NSP == 2 && !act[1], 34);
  ON(detected && mode == M_STOP, 35);
  ON(adopted == 0 && NSP == 1, 36);
  ON(COMP_CYCLE && mode == M_STOP && reason == R_MAXT && NSP == 1, 37);
  ON(adopted != NONE && TRUE_AGE(adopted) == tmax, 38);
  ON(COMP_CYCLE && was_conf[0] > 0 && was_conf[1] > 0 && dev && act[0] && act[1], 39);
  ON(was_mode == M_STOP && was_reason == R_START && mode == M_TG, 40);
  ON(was_reason == R_START && reason == R_MOVED, 41);
  ON(was_mode == M_STOP && HEALTHY && bal && !trust && mode == M_STOP, 42);
  ON(was_mode == M_STOP && was_reason == R_MOVED && mode == M_TG, 43);
  ON(was_mode == M_STOP && HEALTHY && !was_trust && was_rest == MODEL_WARMUP - 1 && mv && rest == 0, 44);
  ON(was_mode == M_STOP && was_reason == R_MAXT && HEALTHY && bal && mode == M_STOP, 45);
  ON(was_mode == M_STOP && was_reason != R_START && !was_trust && trust && bal && mode == M_TG, 46);
  ON(was_mode == M_STOP && was_reason == R_START && !HEALTHY, 47);
  ON(was_mode == M_STOP && was_trust && HEALTHY && dev && mode == M_STOP && !trust, 48);
  ON(was_mode == M_STOP && was_trust && HEALTHY && was_dcount == CONFIRM - 1 && !dev && trust, 49)
}

inline clear_cycle() {
  dev = 0; sa[0] = 0; sa[1] = 0; imu = 0; tg = 0; bal = 0; mv = 0; sec = 0; sage = 0;
  detected = 0; breset = 0; adopted = NONE;
  was_mode = 0; was_reason = 0; was_dcount = 0; was_tmax = 0; was_margin = 0; was_rest = 0; c = 0;
  was_trust = 0;
  was_act[0] = 0; was_act[1] = 0; was_conf[0] = 0; was_conf[1] = 0;
  g_mint = 0; g_mmax = 0;
  /* ghosts outside their use: the run outside TG odometry, the episode outside compensation */
  if :: mode != M_TG -> g_run = 0 :: else -> skip fi;
  if
  :: mode != M_COMP -> g_ep = 0; g_sage = 0; g_since = 0; g_seen = 0; g_hist[0] = 0; g_hist[1] = 0
  :: else -> skip
  fi
}

init {
  do
  :: atomic {
#ifdef WALK
       ncycles < MODEL_CYCLES -> ncycles++;
#endif
       CLEAR_GOALS;
       /* the environment (see the header comment for the inputs fixed when not read) */
#if defined(UNIT)
       unit_inputs();
#else
       CHOOSE_SEC(sec); CHOOSE_OK(imu); CHOOSE_OK(tg); CHOOSE_BALISE(bal);
#endif
#if defined(WALK) && !defined(UNIT)
       if :: mode == M_COMP -> CHOOSE_UNLIKELY(dev) :: else -> CHOOSE_LIKELY(dev) fi;
       CHOOSE_MOTION(mv);
       CHOOSE_LIKELY(sa[0]); CHOOSE_LIKELY(sa[1]); CHOOSE_AGE(sage);
#elif !defined(WALK)
       if :: HEALTHY && (mode != M_STOP || trust) -> CHOOSE_BIT(dev) :: else -> skip fi;
       if :: HEALTHY && !trust -> CHOOSE_BIT(mv) :: else -> skip fi;
       if
       :: HEALTHY && mode == M_COMP ->
          CHOOSE_BIT(sa[0]);
          if :: NSP == 2 -> CHOOSE_BIT(sa[1]) :: else -> skip fi
       :: else -> skip
       fi;
       if :: HEALTHY && mode == M_TG && dev -> CHOOSE_AGE(sage) :: else -> sage = MODEL_START_AGE fi;
#endif
       d_step {
         printf("@IN cycle dev=%d sa0=%d sa1=%d imu=%d tg=%d bal=%d mv=%d sec=%d age=%d\n",
                dev, sa[0], sa[1], imu, tg, bal, mv, sec, sage);
         was_mode = mode; was_reason = reason; was_dcount = dcount; was_tmax = tmax;
         was_rest = rest; was_trust = trust;
         was_margin = margin; was_act[0] = act[0]; was_act[1] = act[1];
         was_conf[0] = conf[0]; was_conf[1] = conf[1];
         cycle();
         printf("@OUT mode=%d reason=%d dcount=%d a0=%d t0=%d c0=%d a1=%d t1=%d c1=%d tmax=%d margin=%d stop=%d valid=%d det=%d adopted=%d breset=%d trust=%d rest=%d\n",
                mode, reason, dcount, act[0], age[0], conf[0], act[1], age[1], conf[1], tmax, margin,
                stop, valid, detected, adopted, breset, trust, rest);
         ghost();
         check();
         goals();
#ifdef UNIT
         /* the walks check every property at the unit's times as they go */
         assert(!(v_detect || v_start || v_readh || v_timeout || v_stopped || v_limits || v_parallel ||
                  v_balise || v_sensor || v_startup));
         /* the history index of this cycle is hl: the start points are one at the oldest usable entry */
         if :: detected -> eps = 1; u_same = (sage == hl - MODEL_WARMUP) :: else -> skip fi;
         if :: HEALTHY -> if :: hl < HL_CAP -> hl++ :: else -> skip fi :: else -> hl = 0 fi;
#endif
         clear_cycle()
       }
     }
  od
}

// @property REQ_RA_003_detection REQ-RA-003 : in TG odometry with healthy sensors a slip/slide is detected (the machine leaves TG odometry, detection event) exactly in the cycle that completes MODEL_CONFIRM consecutive deviations: never missed, never earlier; compensation only after such a detection
ltl REQ_RA_003_detection { [] !v_detect }
// @property REQ_RA_004_start_point REQ-RA-004 REQ-RA-010 : every candidate compensates from its start point: while compensating its age is the start-point age found at detection (MODEL_START_AGE + 0..MODEL_SEARCH_EXTRA, the second start point MODEL_SPACING cycles older) plus the cycles since the detection
ltl REQ_RA_004_start_point { [] !v_start }
// @property REQ_RA_006_readhesion REQ-RA-006 : compensation returns to TG odometry only by adopting a candidate that had no deviation and the speed agreement in each of the last MODEL_CONFIRM cycles since the detection (ghost history of the inputs)
ltl REQ_RA_006_readhesion { [] !v_readh }
// @property REQ_RA_007_timeout REQ-RA-007 : while compensating, exactly the candidates whose true age is within every maximum compensation time of the episode are active, never older than the t_max in force; in the cycle the last candidate times out (also at detection) the stop demand and the invalid position are given
ltl REQ_RA_007_timeout { [] !v_timeout }
// @property REQ_RA_007_stopped REQ-RA-007 REQ-RA-012 : the stop demand and the invalid position are given exactly in the stopped state, which keeps its reason and is held until a balise is read with both sensors healthy, which re-establishes TG odometry
ltl REQ_RA_007_stopped { [] !v_stopped }
// @property REQ_RA_009_limits REQ-RA-009 : the margin in force is never below, and the maximum compensation time in force never above, the limits of the section under the train in the current cycle and of every section of every cycle since the episode began
ltl REQ_RA_009_limits { [] !v_limits }
// @property REQ_RA_010_parallel REQ-RA-010 : the adopted candidate is the lowest index that completed its confirmation within its maximum compensation time, in the first cycle any did (the primary if both do in the same cycle); nothing stays active after the adoption
ltl REQ_RA_010_parallel { [] !v_parallel }
// @property REQ_RA_012_balise REQ-RA-012 : a balise read in TG odometry with healthy sensors (and the balise that ends a stop) resets the accumulated error in that cycle; there is no reset without a balise and none while compensating
ltl REQ_RA_012_balise { [] !v_balise }
// @property REQ_RA_015_startup REQ-RA-015 REQ-RA-007 : the position is valid only while the TG history is trusted, i.e. after a warm-up of MODEL_WARMUP healthy cycles without a TG pulse since the last stop or the start-up, not withdrawn by MODEL_CONFIRM deviations in a row while stopped; the start-up stop ends without a balise only if no TG pulse and no sensor failure came before the trust, and then in the cycle the warm-up completes; every other stop needs the trust and a balise
ltl REQ_RA_015_startup { [] !v_startup }
// @property REQ_RA_013_sensor REQ-RA-013 : an IMU or TG failure gives in the same cycle the stopped state with the failure as reason (IMU checked first), the stop demand and the invalid position, and discards every candidate
ltl REQ_RA_013_sensor { [] !v_sensor }

// @walks UNIT : the on-board unit's environment (random walks only, ra.unit.jsonl, replayed through the unit's sensor interface): the unit's times and the input sequences a TG and IMU stream can give the machine (unit_inputs())
// @variant ONE_START start_points=1 : one start point (parallel_start_points = 1): every property is verified with a single candidate too, and the configuration supplies the vectors of ra.one_start.jsonl

// @mutant MUTANT_TIMEOUT_OFF_BY_ONE violates REQ_RA_007_timeout : a candidate times out only above t_max + 1 (C++ FAULT_RA_TIMEOUT_OFF_BY_ONE)
// @mutant MUTANT_CONFIRM_TWO violates REQ_RA_006_readhesion : re-adhesion adopted after MODEL_CONFIRM - 1 confirming cycles (C++ FAULT_RA_CONFIRM_TWO)
// @mutant MUTANT_SPEED_IGNORED violates REQ_RA_006_readhesion : the speed condition of the re-adhesion judgement is ignored (C++ FAULT_RA_SPEED_IGNORED)
// @mutant MUTANT_EPISODE_RELAXES violates REQ_RA_009_limits : the episode takes the current section's limits only (C++ FAULT_RA_EPISODE_RELAXES)
// @mutant MUTANT_LAST_CANDIDATE_WINS violates REQ_RA_010_parallel : the highest index wins when both candidates complete the confirmation in one cycle (C++ FAULT_RA_LAST_CANDIDATE_WINS)
// @mutant MUTANT_TG_FAILURE_IGNORED violates REQ_RA_013_sensor : a TG failure does not stop the train (C++ FAULT_RA_TG_FAILURE_IGNORED)
// @mutant MUTANT_START_AT_DETECTION violates REQ_RA_004_start_point : the compensation starts at the detection cycle instead of the start point found by the search
// @mutant MUTANT_NO_SPACING violates REQ_RA_004_start_point : the second start point starts at the primary's age (no parallel spacing)
// @mutant MUTANT_MARGIN_LATE violates REQ_RA_009_limits : the margin in force follows the section one cycle late
// @mutant MUTANT_DETECT_EARLY violates REQ_RA_003_detection : detection after MODEL_CONFIRM - 1 consecutive deviations
// @mutant MUTANT_DETECT_LATE violates REQ_RA_003_detection : detection only after MODEL_CONFIRM + 1 consecutive deviations (a slip missed)
// @mutant MUTANT_STOP_POSITION_VALID violates REQ_RA_007_timeout : the timeout demands a stop without declaring the position invalid
// @mutant MUTANT_RELEASED_WITHOUT_BALISE violates REQ_RA_007_stopped : the stopped state is left as soon as both sensors are healthy, without a balise
// @mutant MUTANT_BALISE_IGNORED_IN_TG violates REQ_RA_012_balise : a balise in TG odometry does not reset the accumulated error
// @mutant MUTANT_CONFIRM_NOT_RESET violates REQ_RA_006_readhesion : a cycle without both conditions does not restart the confirmation (non-consecutive cycles counted)
// @mutant MUTANT_DEVIATION_IGNORED violates REQ_RA_006_readhesion : the deviation condition of the re-adhesion judgement is ignored
// @mutant MUTANT_OTHER_KEPT violates REQ_RA_010_parallel : the candidate not adopted stays active after the adoption
// @mutant MUTANT_FAILURE_KEEPS_CANDIDATES violates REQ_RA_013_sensor : a sensor failure stops the train but keeps the candidates
// @mutant MUTANT_NO_WARMUP violates REQ_RA_015_startup : the odometry starts in TG odometry with a valid position, without a warm-up (the former start-up)
// @mutant MUTANT_WARMUP_COUNTS_MOTION violates REQ_RA_015_startup : the warm-up counts cycles with TG pulses (a start in motion is trusted)
// @mutant MUTANT_BALISE_WITHOUT_WARMUP violates REQ_RA_015_startup : a balise ends a stop before the history is trusted (a timeout or failure in motion)
// @mutant MUTANT_START_MOVED_IGNORED violates REQ_RA_015_startup : a start in motion ends with the warm-up, without a balise
// @mutant MUTANT_TRUST_KEPT_ON_STOP violates REQ_RA_015_startup : a timeout keeps the history trusted (no warm-up after a stop)
// @mutant MUTANT_TRUST_KEPT_ON_DEVIATION violates REQ_RA_015_startup : a deviation run while stopped keeps the history trusted (C++ FAULT_RA_TRUST_KEPT_ON_DEVIATION)

// ---- coverage goals (trap properties): every branch of the cycle, each boundary ----
// @goal 0 REQ-RA-003 REQ-RA-010 : detection after MODEL_CONFIRM consecutive deviations, both start points compensating
// @goal 1 REQ-RA-003 : boundary: MODEL_CONFIRM - 1 consecutive deviations, then none: no detection, the count restarts
// @goal 2 REQ-RA-003 REQ-RA-012 : detection in a cycle with a balise (accumulated error reset in the detection cycle)
// @goal 3 REQ-RA-003 REQ-RA-004 : boundary: detection with the start point at the end of the search (age MODEL_START_AGE + MODEL_SEARCH_EXTRA)
// @goal 4 REQ-RA-006 REQ-RA-010 : boundary: primary adopted at the first possible cycle, exactly MODEL_CONFIRM confirming cycles after the detection
// @goal 5 REQ-RA-006 : boundary: MODEL_CONFIRM - 1 confirming cycles, then a deviation: the confirmation restarts
// @goal 6 REQ-RA-006 : speed condition failing without a deviation: the confirmation restarts
// @goal 7 REQ-RA-006 : re-adhesion after an interrupted confirmation (later than the first possible cycle)
// @goal 8 REQ-RA-010 : the second start point is adopted while the primary is still compensating
// @goal 9 REQ-RA-010 : boundary: the second start point wins with the primary one confirming cycle short
// @goal 10 REQ-RA-010 : both start points complete the confirmation in the same cycle: the primary is adopted
// @goal 11 REQ-RA-010 REQ-RA-007 : primary adopted in the cycle the second start point times out
// @goal 12 REQ-RA-007 : boundary: the primary compensating at exactly t_max (still active)
// @goal 13 REQ-RA-007 : boundary: the last candidate times out at t_max + 1: stop demand and invalid position in that cycle
// @goal 14 REQ-RA-007 REQ-RA-010 : the second start point times out, the primary continues
// @goal 15 REQ-RA-007 REQ-RA-009 : a tight section entered during the episode shortens t_max and times out the compensation: stop demand
// @goal 16 REQ-RA-009 : a tight section entered during the episode shortens t_max, the compensation continues
// @goal 17 REQ-RA-009 : a steep section entered during the episode raises the margin in force
// @goal 18 REQ-RA-009 : boundary: the episode keeps a margin above the current section's
// @goal 19 REQ-RA-009 : boundary: the episode keeps a t_max below the current section's
// @goal 20 REQ-RA-009 : in TG odometry the limits follow the current section (margin lowered after an episode or a steep section)
// @goal 21 REQ-RA-013 : IMU failure in TG odometry
// @goal 22 REQ-RA-013 : IMU failure while compensating: every candidate discarded
// @goal 23 REQ-RA-013 : IMU failure while stopped after a timeout: the reason becomes the IMU failure
// @goal 24 REQ-RA-013 : TG failure in TG odometry
// @goal 25 REQ-RA-013 : TG failure while compensating: every candidate discarded
// @goal 26 REQ-RA-013 : TG failure while stopped
// @goal 27 REQ-RA-013 : IMU and TG failing together: the IMU failure is reported
// @goal 28 REQ-RA-012 : balise in TG odometry: accumulated error reset
// @goal 29 REQ-RA-012 : balise while compensating: no reset, the compensation continues
// @goal 30 REQ-RA-007 REQ-RA-012 : balise while stopped after a timeout: position re-established, TG odometry
// @goal 31 REQ-RA-013 REQ-RA-012 : balise with both sensors healthy again after a sensor failure: position re-established
// @goal 32 REQ-RA-007 REQ-RA-013 : balise while stopped with a sensor still failing: stop held
// @goal 33 REQ-RA-007 : stopped without a balise (sensors healthy): stop demand held
// @goal 34 REQ-RA-007 REQ-RA-010 : the second start point discarded at detection (older than t_max), the primary compensating
// @goal 35 REQ-RA-007 : every start point older than t_max at detection: stop demand in the detection cycle
// @goal 36 REQ-RA-010 REQ-RA-006 : one start point: the single candidate adopted [config ONE_START]
// @goal 37 REQ-RA-007 : one start point: the single candidate times out: stop demand [config ONE_START]
// @goal 38 REQ-RA-006 REQ-RA-007 : boundary: re-adhesion in the cycle the adopted candidate reaches exactly t_max
// @goal 39 REQ-RA-006 : a deviation while compensating restarts the confirmation of both start points
// @goal 40 REQ-RA-015 : start-up at standstill: the warm-up completes, TG odometry with the start-up position (no balise needed)
// @goal 41 REQ-RA-015 : a TG pulse during the start-up: a start in motion (reason START_IN_MOTION)
// @goal 42 REQ-RA-015 REQ-RA-007 : a balise while stopped before the history is trusted: the stop is held
// @goal 43 REQ-RA-015 : a start in motion ends after a warm-up at standstill and a balise
// @goal 44 REQ-RA-015 : boundary: MODEL_WARMUP - 1 cycles at standstill, then a TG pulse: the warm-up restarts
// @goal 45 REQ-RA-015 REQ-RA-007 : a balise after a timeout before the warm-up at standstill: the stop is held
// @goal 46 REQ-RA-015 REQ-RA-007 : boundary: the warm-up completes in the cycle of a balise: the stop ends in that cycle
// @goal 47 REQ-RA-015 REQ-RA-013 : a sensor failure during the start-up
// @goal 48 REQ-RA-015 REQ-RA-003 : MODEL_CONFIRM deviations while stopped with the history trusted: the trust is withdrawn
// @goal 49 REQ-RA-015 : boundary: MODEL_CONFIRM - 1 deviations while stopped, then none: the trust holds

#ifdef TRAPS
#include "ra_goals.pml"
#endif
