/*
 * railproof — moving block: train tracking, stop-limit generation and virtual-block
 * interlocking on the ground, stop-limit reception on board (D5 §5.1.3, §5.1.4, §5.2).
 *
 * What is modelled (spec/design/mb.md §3). NT trains on one line of
 * MODEL_BLOCKS virtual blocks of MODEL_BLOCK_UNITS units each (a unit is model_unit_mm
 * on the real line). Trains run in increasing position and occupy LEN units ending at
 * their front. The line holds a station platform handled as a fixed block (also the only
 * set-back section), a set of points with an automatic main route and a conflicting
 * siding route, a possession area, a radio handover point, a system boundary and the end
 * of track (positions in spec/parameters/mb.yaml).
 *
 * The environment does, nondeterministically, everything the ground does not control:
 * - trains move one unit at a time, at any speed, but never beyond their usable on-board
 *   stop limit (ASM-013: the braking supervision discharges this); inside the platform a
 *   train may set back one unit (REQ-MB-005);
 * - position reports (front, length correction) reach the ground at any time or are lost;
 *   tracking is abnormal once no report has arrived for more than T_TRACK cycles;
 * - the stop-limit telegram issued to a train each cycle is delivered at once, lost, or
 *   held back (one per train) and delivered later in any order with newer ones; the
 *   telegram layer tells the on-board unit each telegram's age (REQ-TG-006, ASM-014);
 * - system management requests and cancels a possession, a shunting movement asks for
 *   the siding route and later frees it, the next radio cell secures a train's channel,
 *   the neighbouring system accepts trains over the boundary.
 * One tick is one ground cycle (model_tick_ms); ground and on-board clocks advance together.
 *
 * The ground cycle runs in the order of cpp/runtime/mb/src/wayside/ground.cpp (design note §4):
 * ageing and tracking timeout; interlocking (release of the automatic main route for a
 * requested siding route, setting the siding route, re-setting the main route, point
 * moves); possession confirmation; the stop limit of every tracked train = the nearest
 * obstruction minus its margin; one telegram per tracked train. What the ground still
 * protects for a train is the largest stop limit it issued within the on-board validity
 * window (ages 0..A_LINK): the train may still be using any of them.
 *
 * Configurations (-D): default = the full size (MODEL_TRAINS trains); TRAINS2 / TRAINS4
 * change the number of trains (model-checking cost table in the README); FAIR = a
 * healthy system (every report and telegram arrives in the cycle, no possession or
 * siding request) for the progress property.
 *
 * Properties are evaluated by check() after every step into latched ghost bits v_*;
 * each LTL property says one of them never becomes 1.
 *
 * Annotations read by testgen: see models/tg.pml.
 */
// @pan_flags -DCOLLAPSE
#include "mb_params.pml"

/* Verification configurations (spec/design/mb.md §5): */
#ifdef CORE            /* 2 trains over the whole line, every report, tracking, set-back and
                          telegram fault (loss, delay, re-ordering); no infrastructure commands */
#define TRAINS2
#define NO_ENV
#endif
#ifdef TRIO            /* 3 trains, every fault as CORE, confined to the first blocks: the next
                          radio cell is never secured, so the handover point (with the platform,
                          the only fixed block and set-back section, before it) ends their run */
#define NO_ENV
#define NO_PRESET
#endif
#ifdef FEATURE_POSS    /* 2 trains, possessions requested and cancelled */
#define TRAINS2
#define NO_HOLD
#define ENV_POSS
#endif
#ifdef FEATURE_ROUTE   /* 2 trains, siding route requested and freed over the points */
#define TRAINS2
#define NO_HOLD
#define ENV_ROUTE
#endif
#ifdef FEATURE_RADIO   /* 2 trains, radio cells secured and the boundary accepted at any time */
#define TRAINS2
#define NO_HOLD
#define ENV_RADIO
#endif
#ifdef FAIR
#define NO_ENV
#endif

#if defined(TRAINS2)
#define NT 2
#elif defined(TRAINS4)
#define NT 4
#else
#define NT MODEL_TRAINS
#endif
#define NU MODEL_LINE_UNITS
#define LEN MODEL_TRAIN_UNITS
#define T_TRACK MODEL_TRACK_TIMEOUT_TICKS
#define A_MAX MODEL_MAX_AGE_TICKS
#define A_LINK MODEL_LINK_TICKS
#define PF_U MODEL_PLATFORM_FIRST_UNIT
#define PL_U MODEL_PLATFORM_LAST_UNIT
#define PT_F MODEL_POINTS_FIRST_UNIT
#define PT_L MODEL_POINTS_LAST_UNIT
#define RT_L MODEL_ROUTE_LAST_UNIT
#define PS_F MODEL_POSSESSION_FIRST_UNIT
#define PS_L MODEL_POSSESSION_LAST_UNIT
#define HO MODEL_HANDOVER_UNIT
#define SB MODEL_BOUNDARY_UNIT
#define EOT NU              /* the buffer stop: the first position beyond the last unit */

#ifdef MUTANT_NO_TRAIN_MARGIN
#define M_TRAIN 0
#else
#define M_TRAIN MODEL_MARGIN_TRAIN
#endif
#define M_FB MODEL_MARGIN_FIXED_BLOCK
#define M_RT MODEL_MARGIN_ROUTE
#define M_HO MODEL_MARGIN_HANDOVER
#define M_SB MODEL_MARGIN_BOUNDARY
#ifdef MUTANT_NO_POSSESSION_MARGIN
#define M_PS 0
#else
#define M_PS MODEL_MARGIN_POSSESSION
#endif
#define M_AB MODEL_MARGIN_ABNORMAL
#define M_EOT MODEL_MARGIN_EOT

/* obstruction kinds (why a stop limit is where it is), numbered as in D5 §5.1.4 */
#define W_NONE 0
#define W_TRAIN 1
#define W_FIXED 2
#define W_ROUTE 3
#define W_HANDOVER 4
#define W_BOUNDARY 5
#define W_POSSESSION 6
#define W_ABNORMAL 7
#define W_EOT 8
/* on-board verdicts */
#define V_ACCEPT 0
#define V_TOO_OLD 1
#define V_NOT_NEWER 2
/* environment commands */
#define E_POSS_REQ 1
#define E_POSS_CANCEL 2
#define E_SIDE_REQ 3
#define E_SIDE_FREE 4
#define E_SECURE 5
#define E_EXIT_OK 6
/* possession states */
#define P_NONE 0
#define P_REQUESTED 1
#define P_ACTIVE 2
#define NOTEL (-9)           /* below every real limit (the smallest is -3) */
/* what happens to a telegram when it is issued */
#define C_NOW 0
#define C_LOST 1
#define C_HELD 2

/* ---- true state of the trains (environment) ------------------------------------------ */
byte front[NT];          /* front unit */
bit  sb[NT];             /* has set back one unit since its last forward move */
/* ---- on-board authority ---------------------------------------------------------------- */
short ob_lim[NT];        /* on-board stop limit: the last unit the front may reach */
byte ob_age[NT];         /* age of the telegram it came from, saturating at A_LINK + 1 */
/* ---- channel: one held-back telegram per train ------------------------------------------ */
short tl_lim[NT];        /* NOTEL: none */
byte tl_age[NT];
/* ---- ground ------------------------------------------------------------------------------ */
byte g_front[NT];        /* last reported front */
byte g_ext[NT];          /* last reported length correction */
byte g_age[NT];          /* cycles since the last report, saturating at T_TRACK + 1 */
bit  abn[NT];            /* tracking abnormal */
short grant[NT];         /* stop limit issued this cycle; the frozen bound when abnormal */
short hist[NT * (A_LINK + 1)];  /* limits issued 0..A_LINK cycles ago (NOTEL: none) */
bit  sec[NT];            /* radio channel in the next cell secured for the train */
bit  exit_ok;            /* the neighbouring system accepts trains over the boundary */
bit  r_main;             /* automatic main route over the points set and locked */
bit  r_side;             /* siding route over the points set and locked */
bit  req_side;           /* a shunting movement asks for the siding route */
bit  pts_rev;            /* points reverse */
byte poss;               /* possession state */
bit  ready;              /* the initial state is set up (properties hold from here) */
/* ---- ghost: latched property violations and goal flags -------------------------------- */
bit  v_sep, v_lim, v_stale, v_points, v_routes, v_poss, v_back;
bit  v_behind;           /* FAIR: a train's authority differs from what the true line allows */
#ifdef TRAPS
bit g[40];
#endif

/* scratch of one atomic step, cleared at its end so that it never tells states apart
 * (BFS forbids hidden variables) */
short h_best, h_auth, h_x;
byte h_i, h_j, h_why, h_t, h_v, h_c;
int h_occ;
inline clear_scratch() {
  h_best = 0; h_auth = 0; h_x = 0; h_i = 0; h_j = 0; h_why = 0; h_t = 0; h_v = 0; h_c = 0; h_occ = 0
}

#define REAR(t) (front[t] - LEN + 1)
/* length correction reported by the on-board unit: grows with the distance run since the
 * last balise (one every MODEL_BALISE_SPACING_UNITS units), REQ-MB-002 */
#define EXT_OF(p) (((p) % MODEL_BALISE_SPACING_UNITS) / MODEL_ODO_UNITS_PER_EXT > MODEL_EXT_MAX -> \
                   MODEL_EXT_MAX : ((p) % MODEL_BALISE_SPACING_UNITS) / MODEL_ODO_UNITS_PER_EXT)
/* the ground's extended occupied range of a train, REQ-MB-003 */
#define G_REAR(t) (g_front[t] - LEN + 1 - g_ext[t])
#define G_FRONT(t) (abn[t] && grant[t] > g_front[t] + g_ext[t] -> grant[t] : g_front[t] + g_ext[t])
#define OVERLAPS(a, b, lo, hi) ((a) <= (hi) && (b) >= (lo))
#define USABLE(t) (ob_age[t] <= A_LINK)
#define HIST(t, k) hist[(t) * (A_LINK + 1) + (k)]

#ifdef TRAPS
/* goal flags mark the goals reached in the last step only (cleared at the start of each
 * step), so that they do not multiply the states of the breadth-first trap searches */
#define GOAL(k) g[k] = 1
#define CLEAR_GOALS d_step { for (h_i : 0 .. 39) { g[h_i] = 0 }; h_i = 0 }
#else
#define CLEAR_GOALS skip
#define GOAL(k) skip
#endif

/* what the ground still protects for train t: the largest limit issued in the validity
 * window, or the frozen bound of an abnormal train (REQ-MB-009) */
inline protected(t) {
  h_auth = NOTEL;
  for (h_j : 0 .. A_LINK) {
    if
    :: HIST(t, h_j) > h_auth -> h_auth = HIST(t, h_j)
    :: else -> skip
    fi
  }
  if
  :: abn[t] && grant[t] > h_auth -> h_auth = grant[t]
  :: else -> skip
  fi
}

inline consider(x, w) {
  if
  :: (x) < h_best -> h_best = (x); h_why = w
  :: else -> skip
  fi
}

/* The stop limit of tracked train t from the ground's data: the nearest obstruction
 * ahead minus its margin (D5 §5.1.4, REQ-MB-006). */
inline stop_limit(t) {
  h_best = EOT - 1 - M_EOT; h_why = W_EOT;
  for (h_i : 0 .. NT - 1) {
    if
    :: h_i != t && g_front[h_i] > g_front[t] ->
       if
#ifndef MUTANT_ABNORMAL_RELEASED
       :: abn[h_i] -> consider(G_REAR(h_i) - 1 - M_AB, W_ABNORMAL)
#else
       :: abn[h_i] -> skip
#endif
       :: else -> consider(G_REAR(h_i) - 1 - M_TRAIN, W_TRAIN)
       fi
    :: else -> skip
    fi
  }
  if  /* fixed block: the platform admits one train */
  :: g_front[t] < PF_U ->
     for (h_i : 0 .. NT - 1) {
       if
#ifndef MUTANT_NO_FIXED_BLOCK
       :: h_i != t && OVERLAPS(G_REAR(h_i), G_FRONT(h_i), PF_U, PL_U) -> consider(PF_U - 1 - M_FB, W_FIXED)
#endif
       :: else -> skip
       fi
     }
  :: else -> skip
  fi;
  if
  :: !r_main && g_front[t] < PT_F -> consider(PT_F - 1 - M_RT, W_ROUTE)
  :: else -> skip
  fi;
  if
  :: !sec[t] && g_front[t] < HO -> consider(HO - 1 - M_HO, W_HANDOVER)
  :: else -> skip
  fi;
  if
  :: !exit_ok && g_front[t] < SB -> consider(SB - 1 - M_SB, W_BOUNDARY)
  :: else -> skip
  fi;
  if
  :: poss != P_NONE && g_front[t] < PS_F -> consider(PS_F - 1 - M_PS, W_POSSESSION)
  :: else -> skip
  fi
}

/* some train's extended range overlaps [lo, hi], or a train short of it may still use
 * authority reaching within the margin m of it (REQ-MB-011, REQ-MB-013, REQ-MB-014) */
inline in_use(lo, hi, m) {
  h_v = 0;
  for (h_i : 0 .. NT - 1) {
    protected(h_i);
    if
    :: OVERLAPS(G_REAR(h_i), G_FRONT(h_i), lo, hi) -> h_v = 1
#ifndef MUTANT_LOCK_IGNORES_AUTHORITY
    :: G_FRONT(h_i) < lo && h_auth >= lo - m -> h_v = 1
#endif
    :: else -> skip
    fi
  }
}

inline move_points(rev) {
  for (h_i : 0 .. NT - 1) {   /* ghost check: a train on the points or a locked route */
    if
    :: OVERLAPS(REAR(h_i), front[h_i], PT_F, PT_L) -> v_points = 1
    :: else -> skip
    fi
  }
  if
  :: r_main || r_side -> v_points = 1
  :: else -> skip
  fi;
  pts_rev = rev
}

inline ground_cycle() {
  /* 1. clocks: validity window, channel, on-board; tracking timeout (REQ-MB-004) */
  for (h_t : 0 .. NT - 1) {
    for (h_j : 0 .. A_LINK - 1) {
      HIST(h_t, A_LINK - h_j) = HIST(h_t, A_LINK - h_j - 1)
    }
    HIST(h_t, 0) = NOTEL;
    if
    :: tl_lim[h_t] != NOTEL && tl_age[h_t] > A_MAX -> tl_lim[h_t] = NOTEL; tl_age[h_t] = 0
    :: tl_lim[h_t] != NOTEL && tl_age[h_t] <= A_MAX -> tl_age[h_t]++
    :: else -> skip
    fi;
    if
    :: ob_age[h_t] == A_LINK -> ob_age[h_t]++; GOAL(18)   /* authority expires */
    :: ob_age[h_t] < A_LINK -> ob_age[h_t]++
    :: else -> skip
    fi;
    if
    :: g_age[h_t] <= T_TRACK -> g_age[h_t]++
    :: else -> skip
    fi;
    if
    :: g_age[h_t] > T_TRACK && !abn[h_t] ->
       protected(h_t); grant[h_t] = h_auth; abn[h_t] = 1; GOAL(2)
    :: else -> skip
    fi
  }
  /* 2. interlocking on virtual-block occupancy (D5 §5.2, REQ-MB-010..013) */
  if
  :: req_side && r_main ->
     in_use(PT_F, RT_L, M_RT);
     if
#ifndef MUTANT_ROUTE_RELEASED_IN_USE
     :: !h_v -> r_main = 0; GOAL(19)
     :: else -> GOAL(20)
#else
     :: r_main = 0; GOAL(19)
#endif
     fi
  :: else -> skip
  fi;
  if
#ifndef MUTANT_CONFLICTING_ROUTES
  :: req_side && !r_main && !r_side ->
#else
  :: req_side && !r_side ->
#endif
     in_use(PT_F, PT_L, M_RT);
     if
     :: !h_v ->
        if
        :: !pts_rev -> move_points(1)
        :: else -> skip
        fi;
        r_side = 1; req_side = 0; GOAL(21)
     :: else -> GOAL(22)
     fi
  :: else -> skip
  fi;
  if
  :: !r_main && !r_side && !req_side ->
     in_use(PT_F, PT_L, M_RT);
     if
     :: !h_v ->
        if
        :: pts_rev -> move_points(0)
        :: else -> skip
        fi;
        r_main = 1; GOAL(23)
     :: else -> GOAL(24)
     fi
  :: else -> skip
  fi;
  /* 3. possession confirmation: active once no train is in it or may still use authority
   *    reaching within its margin (REQ-MB-014) */
  if
  :: poss == P_REQUESTED ->
     h_c = 1;
     for (h_t : 0 .. NT - 1) {
       protected(h_t);
       if
       :: OVERLAPS(G_REAR(h_t), G_FRONT(h_t), PS_F, PS_L) -> h_c = 0
       :: G_FRONT(h_t) < PS_F && h_auth >= PS_F - M_PS -> h_c = 0
       :: else -> skip
       fi
     }
#ifdef MUTANT_POSSESSION_NO_CONFIRM
     h_c = 1;
#endif
     if
     :: h_c -> poss = P_ACTIVE; GOAL(26)
     :: else -> GOAL(27)
     fi
  :: else -> skip
  fi;
  /* 4. stop limits and one telegram per tracked train */
  for (h_t : 0 .. NT - 1) {
    if
    :: !abn[h_t] ->
       stop_limit(h_t);
       if
       :: h_best < grant[h_t] -> GOAL(13)
       :: else -> skip
       fi;
       grant[h_t] = h_best;
       HIST(h_t, 0) = h_best;
       printf("@OUT train t=%d grant=%d why=%d abn=0 usable=%d\n", h_t, h_best, h_why, USABLE(h_t));
       if
       :: h_why == W_TRAIN -> GOAL(4)
       :: h_why == W_FIXED -> GOAL(5)
       :: h_why == W_ROUTE -> GOAL(6)
       :: h_why == W_HANDOVER -> GOAL(7)
       :: h_why == W_BOUNDARY -> GOAL(8)
       :: h_why == W_POSSESSION -> GOAL(9)
       :: h_why == W_ABNORMAL -> GOAL(10)
       :: h_why == W_EOT -> GOAL(11)
       fi
    :: else ->
       printf("@OUT train t=%d grant=%d why=0 abn=1 usable=%d\n", h_t, grant[h_t], USABLE(h_t))
    fi
  }
  h_occ = 0;
  for (h_t : 0 .. MODEL_BLOCKS - 1) {
    for (h_i : 0 .. NT - 1) {
      if
      :: OVERLAPS(G_REAR(h_i), G_FRONT(h_i), h_t * MODEL_BLOCK_UNITS,
                  h_t * MODEL_BLOCK_UNITS + MODEL_BLOCK_UNITS - 1) -> h_occ = h_occ | (1 << h_t)
      :: else -> skip
      fi
    }
  }
  printf("@OUT il main=%d side=%d pts=%d poss=%d occ=%d\n", r_main, r_side, pts_rev, poss, h_occ)
}

/* on-board reception of a stop-limit telegram (cpp/runtime/mb/src/onboard/authority.cpp, REQ-MB-009) */
inline receive(t, lim, age) {
  printf("@IN deliver t=%d lim=%d age=%d\n", t, lim, age);
  if
  :: age > A_MAX -> h_v = V_TOO_OLD; GOAL(15)
#ifndef MUTANT_ACCEPT_NOT_NEWER
  :: age <= A_MAX && USABLE(t) && age >= ob_age[t] -> h_v = V_NOT_NEWER; GOAL(16)
#ifdef MUTANT_ONBOARD_KEEPS_FIRST
  :: age <= A_MAX && USABLE(t) -> h_v = V_NOT_NEWER
#endif
#endif
  :: else ->
     h_v = V_ACCEPT; ob_lim[t] = lim;
     if
     :: age == A_MAX -> GOAL(17)
     :: else -> GOAL(14)
     fi;
#ifndef MUTANT_VALIDITY_FROM_RECEPTION
     ob_age[t] = age
#else
     ob_age[t] = 0
#endif
  fi;
  printf("@OUT ob t=%d verdict=%d lim=%d\n", t, h_v, ob_lim[t])
}

inline late(t) {
  receive(t, tl_lim[t], tl_age[t]); tl_lim[t] = NOTEL; tl_age[t] = 0
}

inline report(t) {
  printf("@IN report t=%d front=%d ext=%d\n", t, front[t], EXT_OF(front[t]));
  if
  :: abn[t] -> GOAL(3)
  :: g_age[t] == T_TRACK -> GOAL(1)
  :: else -> GOAL(0)
  fi;
  g_front[t] = front[t]; g_ext[t] = EXT_OF(front[t]); g_age[t] = 0; abn[t] = 0;
  printf("@OUT report t=%d tracked=1\n", t)
}

#define MAY_ADVANCE(t) (USABLE(t) && front[t] < ob_lim[t] && front[t] + 1 < NU)
/* set back: inside the set-back section (the platform), one unit (REQ-MB-005) */
#ifndef MUTANT_SET_BACK_ANYWHERE
#define MAY_SET_BACK(t) (!sb[t] && REAR(t) > PF_U && front[t] <= PL_U)
#else
#define MAY_SET_BACK(t) (!sb[t] && REAR(t) > 0)
#endif

inline advance(t) {
  if
  :: front[t] == ob_lim[t] - 1 -> GOAL(12)   /* stops exactly at its limit */
  :: else -> skip
  fi;
  front[t]++; sb[t] = 0
}

#ifdef FAIR
/* healthy system: after the cycle, is a train's authority short of what the true line
 * allows (the nearest true obstruction, with the reported corrections, minus its margin)? */
inline progress_check() {
  for (h_t : 0 .. NT - 1) {
    h_best = EOT - 1 - M_EOT;
    for (h_i : 0 .. NT - 1) {
      if
      :: h_i != h_t && front[h_i] > front[h_t] ->
         h_x = REAR(h_i) - EXT_OF(front[h_i]) - 1 - MODEL_MARGIN_TRAIN;
         if :: h_x < h_best -> h_best = h_x :: else -> skip fi
      :: else -> skip
      fi;
      if
      :: h_i != h_t && front[h_t] < PF_U &&
         OVERLAPS(REAR(h_i) - EXT_OF(front[h_i]), front[h_i] + EXT_OF(front[h_i]), PF_U, PL_U) ->
         if :: PF_U - 1 - M_FB < h_best -> h_best = PF_U - 1 - M_FB :: else -> skip fi
      :: else -> skip
      fi
    }
    if
    :: ob_lim[h_t] != h_best -> v_behind = 1
    :: else -> skip
    fi
  }
}
#endif

inline env(cmd, arg) { printf("@IN env cmd=%d arg=%d\n", cmd, arg) }
inline env_out() { printf("@OUT env poss=%d side_req=%d\n", poss, req_side) }


#if NT == 2
#define FOR_TRAINS(M) M(0); M(1)
#elif NT == 3
#define FOR_TRAINS(M) M(0); M(1); M(2)
#else
#define FOR_TRAINS(M) M(0); M(1); M(2); M(3)
#endif

/* One cycle's choices for train t, each a small nondeterministic step: move (forward
 * within the usable authority, set back one unit inside the set-back section, or stand),
 * report delivered or lost, a held-back telegram delivered late or not; after the ground
 * cycle, the fate of the telegram it issued. */
#ifdef NO_SETBACK
#define SET_BACK(t)
#else
#define SET_BACK(t) :: d_step { MAY_SET_BACK(t) -> front[t]--; sb[t] = 1 }
#endif
#define MOVE(t) \
  if \
  :: d_step { MAY_ADVANCE(t) -> advance(t) } \
  SET_BACK(t) \
  :: skip \
  fi
#ifdef FAIR
/* healthy system: every train reports, every telegram arrives at once; no commands but
 * the radio cells and the neighbour, which are set up at the start */
#define REPORT(t) d_step { report(t) }
#define LATE(t) skip
#define CHANNEL(t) d_step { if :: !abn[t] -> receive(t, grant[t], 0) :: else -> skip fi }
#define ENV_COMMAND skip
#define PROGRESS_AFTER d_step { progress_check() }
#else
#define REPORT(t) \
  if \
  :: d_step { report(t) } \
  :: skip \
  fi
#define LATE(t) \
  if \
  :: d_step { tl_lim[t] != NOTEL -> late(t) } \
  :: skip \
  fi
#ifdef NO_HOLD
#define HOLD(t)
#else
#define HOLD(t) :: d_step { !abn[t] && tl_lim[t] == NOTEL -> tl_lim[t] = grant[t]; tl_age[t] = 0 }
#endif
#define CHANNEL(t) \
  if \
  :: d_step { !abn[t] -> receive(t, grant[t], 0) } \
  :: d_step { !abn[t] -> skip }   /* lost */ \
  HOLD(t) \
  :: d_step { abn[t] -> skip } \
  fi
#define PROGRESS_AFTER skip
/* environment commands; the verification configurations ENV_POSS, ENV_ROUTE, ENV_RADIO
 * enable one group each (the others' state is then fixed: radio cells secured and the
 * boundary accepted from the start, no possession, no siding request); NO_ENV none */
#if !defined(ENV_POSS) && !defined(ENV_ROUTE) && !defined(ENV_RADIO) && !defined(NO_ENV)
#define ENV_POSS
#define ENV_ROUTE
#define ENV_RADIO
#endif
#ifdef ENV_POSS
#define POSS_CHOICES \
  :: d_step { poss == P_NONE -> env(E_POSS_REQ, 0); poss = P_REQUESTED; env_out(); GOAL(25) } \
  :: d_step { poss == P_ACTIVE -> env(E_POSS_CANCEL, 0); poss = P_NONE; env_out(); GOAL(28) }
#else
#define POSS_CHOICES
#endif
#ifdef ENV_ROUTE
#define ROUTE_CHOICES \
  :: d_step { !req_side && !r_side -> env(E_SIDE_REQ, 0); req_side = 1; env_out() } \
  :: d_step { r_side -> env(E_SIDE_FREE, 0); r_side = 0; env_out() }
#else
#define ROUTE_CHOICES
#endif
#ifdef ENV_RADIO
#define RADIO_CHOICES \
  :: d_step { !exit_ok -> env(E_EXIT_OK, 0); exit_ok = 1; env_out(); GOAL(30) } \
  SECURE_CHOICES
#else
#define RADIO_CHOICES
#endif
#define ENV_COMMAND \
  if \
  :: skip \
  POSS_CHOICES \
  ROUTE_CHOICES \
  RADIO_CHOICES \
  fi
#define SECURE(t) :: d_step { !sec[t] -> env(E_SECURE, t); sec[t] = 1; env_out(); GOAL(29) }
#if NT == 2
#define SECURE_CHOICES SECURE(0) SECURE(1)
#elif NT == 3
#define SECURE_CHOICES SECURE(0) SECURE(1) SECURE(2)
#else
#define SECURE_CHOICES SECURE(0) SECURE(1) SECURE(2) SECURE(3)
#endif
#endif

/* ---- properties, evaluated on the true state after every step ------------------------- */
inline check() {
  for (h_t : 0 .. NT - 1) {
    if
    :: USABLE(h_t) && !(ob_lim[h_t] <= EOT - 1 - M_EOT &&
          (exit_ok || front[h_t] >= SB || ob_lim[h_t] <= SB - 1 - M_SB) &&
          (sec[h_t] || front[h_t] >= HO || ob_lim[h_t] <= HO - 1 - M_HO) &&
          (r_main || front[h_t] >= PT_F || ob_lim[h_t] <= PT_F - 1 - M_RT) &&
          (poss != P_ACTIVE || front[h_t] >= PS_F || ob_lim[h_t] <= PS_F - 1 - MODEL_MARGIN_POSSESSION)) -> v_lim = 1
    :: else -> skip
    fi;
    protected(h_t);
    if
    :: USABLE(h_t) && ob_lim[h_t] > h_auth -> v_stale = 1
    :: else -> skip
    fi;
    for (h_i : 0 .. NT - 1) {
      if
      :: h_i != h_t && OVERLAPS(REAR(h_i), front[h_i], REAR(h_t), front[h_t]) -> v_sep = 1
      :: else -> skip
      fi;
      if
      :: h_i != h_t && USABLE(h_t) && front[h_i] > front[h_t] && ob_lim[h_t] > REAR(h_i) - 1 - MODEL_MARGIN_TRAIN -> v_lim = 1
      :: else -> skip
      fi;
      if
      :: h_i != h_t && USABLE(h_t) && front[h_t] < PF_U && OVERLAPS(REAR(h_i), front[h_i], PF_U, PL_U) &&
         ob_lim[h_t] > PF_U - 1 - M_FB -> v_lim = 1
      :: else -> skip
      fi
    }
    if
    :: poss == P_ACTIVE && OVERLAPS(REAR(h_t), front[h_t], PS_F, PS_L) -> v_poss = 1
    :: else -> skip
    fi
  }
  if
  :: r_main && r_side -> v_routes = 1
  :: else -> skip
  fi;
  clear_scratch()
}

init {
  atomic {
    front[0] = MODEL_INIT_FRONT_0; front[1] = MODEL_INIT_FRONT_1;
#if NT > 2
    front[2] = MODEL_INIT_FRONT_2;
#endif
#if NT > 3
    front[3] = MODEL_INIT_FRONT_3;
#endif
    for (h_t : 0 .. NT - 1) {
      g_front[h_t] = front[h_t]; g_ext[h_t] = EXT_OF(front[h_t]);   /* provisional position */
      ob_lim[h_t] = front[h_t]; ob_age[h_t] = A_LINK + 1;            /* no authority yet */
      grant[h_t] = front[h_t]; tl_lim[h_t] = NOTEL;
      for (h_j : 0 .. A_LINK) { HIST(h_t, h_j) = NOTEL }
#if (defined(FAIR) || !defined(ENV_RADIO)) && !defined(NO_PRESET)
      sec[h_t] = 1;
#endif
    }
#if (defined(FAIR) || !defined(ENV_RADIO)) && !defined(NO_PRESET)
    exit_ok = 1;
#endif
    r_main = 1; ready = 1;
    clear_scratch()
  }
  do
  :: atomic {
       CLEAR_GOALS;
       /* 1. at most one command of system management / shunting / radio cells / neighbour */
       ENV_COMMAND;
       /* 2. trains move at most one unit */
       FOR_TRAINS(MOVE);
       /* 3. position reports reach the ground or are lost */
       FOR_TRAINS(REPORT);
       /* 4. held-back telegrams are delivered late, or not yet */
       FOR_TRAINS(LATE);
       /* 5. the ground cycle, then the fate of each telegram it issued */
       d_step { printf("@IN tick\n"); ground_cycle() };
       FOR_TRAINS(CHANNEL);
       PROGRESS_AFTER;
       d_step { check() }
     }
  od
}

/* ---- properties ------------------------------------------------------------------------
 * Each is checked in the configurations listed (design note §5); the full default
 * configuration generates the vectors. */
// @property REQ_MB_008_separation REQ-MB-008 REQ-MB-004 REQ-MB-005 : the true occupied ranges of two trains never overlap, under report loss, tracking loss, set-back and telegram loss, delay and re-ordering [config CORE TRIO FEATURE_POSS FEATURE_ROUTE FEATURE_RADIO]
ltl REQ_MB_008_separation { [] !v_sep }
// @property REQ_MB_007_limits REQ-MB-007 REQ-MB-006 REQ-MB-013 REQ-MB-017 REQ-MB-023 : every usable on-board stop limit lies short of every true obstruction (preceding train's rear, occupied fixed block, unset route, unsecured handover, unaccepted boundary, active possession, end of track) by that obstruction's margin [config CORE TRIO FEATURE_POSS FEATURE_ROUTE FEATURE_RADIO]
ltl REQ_MB_007_limits { [] !v_lim }
// @property REQ_MB_009_stale REQ-MB-009 : a usable on-board stop limit never exceeds what the ground currently protects (the limits it issued within the validity window): a stale, delayed or re-ordered telegram never extends authority [config CORE TRIO FEATURE_POSS FEATURE_ROUTE FEATURE_RADIO]
ltl REQ_MB_009_stale { [] !v_stale }
// @property REQ_MB_011_points REQ-MB-011 REQ-MB-013 : the points never move while a train occupies their block or a route over them is set [config FEATURE_ROUTE]
ltl REQ_MB_011_points { [] !v_points }
// @property REQ_MB_012_routes REQ-MB-012 : the main route and the conflicting siding route are never set together [config FEATURE_ROUTE]
ltl REQ_MB_012_routes { [] !v_routes }
// @property REQ_MB_014_possession REQ-MB-014 : no train is ever inside an active possession [config FEATURE_POSS]
ltl REQ_MB_014_possession { [] !v_poss }
// @property REQ_MB_018_progress REQ-MB-018 : in a healthy system, at the end of every cycle every train's authority equals what the true line allows (a moving leader is followed without lag) [config FAIR]
ltl REQ_MB_018_progress { [] !v_behind }

// @mutant MUTANT_NO_TRAIN_MARGIN violates REQ_MB_007_limits : the preceding-train margin is omitted [config CORE]
// @mutant MUTANT_ABNORMAL_RELEASED violates REQ_MB_008_separation : a train with abnormal tracking no longer obstructs [config CORE]
// @mutant MUTANT_NO_FIXED_BLOCK violates REQ_MB_007_limits : an occupied platform (fixed block) is not an obstruction [config TRIO]
// @mutant MUTANT_VALIDITY_FROM_RECEPTION violates REQ_MB_009_stale : the on-board unit counts validity from reception instead of issue [config CORE]
// @mutant MUTANT_LOCK_IGNORES_AUTHORITY violates REQ_MB_011_points : route release and point moves ignore authority still held by trains [config FEATURE_ROUTE]
// @mutant MUTANT_ROUTE_RELEASED_IN_USE violates REQ_MB_011_points : the main route is released on request even while in use [config FEATURE_ROUTE]
// @mutant MUTANT_CONFLICTING_ROUTES violates REQ_MB_012_routes : the siding route is set while the main route is set [config FEATURE_ROUTE]
// @mutant MUTANT_NO_POSSESSION_MARGIN violates REQ_MB_007_limits : the possession margin is omitted [config FEATURE_POSS]
// @mutant MUTANT_POSSESSION_NO_CONFIRM violates REQ_MB_014_possession : a possession becomes active without checking trains and their authority [config FEATURE_POSS]
// @mutant MUTANT_ONBOARD_KEEPS_FIRST violates REQ_MB_018_progress : the on-board unit never replaces a usable authority [config FAIR]

// ---- coverage goals (trap properties), each searched in the configuration named ----
// @goal 0 REQ-MB-001 REQ-MB-003 : position report received, train tracked [config CORE]
// @goal 1 REQ-MB-004 : report arriving at the tracking-timeout edge (age = timeout), still tracked [config CORE]
// @goal 2 REQ-MB-004 : tracking lost at the timeout, frozen bound kept [config CORE]
// @goal 3 REQ-MB-004 : abnormal train reports again and is tracked [config CORE]
// @goal 4 REQ-MB-006 : stop limit at the preceding train's rear [config CORE]
// @goal 5 REQ-MB-006 REQ-MB-010 : stop limit before an occupied fixed block (platform) [config CORE]
// @goal 6 REQ-MB-006 REQ-MB-013 : stop limit at the entrance of an unset route [config FEATURE_ROUTE]
// @goal 7 REQ-MB-006 REQ-MB-017 : stop limit at an unsecured radio handover point [config FEATURE_RADIO]
// @goal 8 REQ-MB-006 REQ-MB-023 : stop limit at the system boundary [config FEATURE_RADIO]
// @goal 9 REQ-MB-006 REQ-MB-014 : stop limit at the start of a possession [config FEATURE_POSS]
// @goal 10 REQ-MB-006 REQ-MB-004 : stop limit at the last known rear of an abnormal train [config CORE]
// @goal 11 REQ-MB-006 REQ-MB-023 : stop limit at the end of track [config CORE]
// @goal 12 REQ-MB-007 : boundary: a train reaches its stop limit exactly (obstruction minus margin) [config CORE]
// @goal 13 REQ-MB-009 : the ground shortens an issued stop limit [config CORE]
// @goal 14 REQ-MB-009 REQ-MB-024 : on board: telegram accepted [config CORE]
// @goal 15 REQ-MB-009 : on board: telegram older than the maximum age rejected [config CORE]
// @goal 16 REQ-MB-009 : on board: telegram not newer than the current authority rejected [config CORE]
// @goal 17 REQ-MB-009 : boundary: telegram accepted at exactly the maximum age [config CORE]
// @goal 18 REQ-MB-009 : on-board authority expires (validity edge) [config CORE]
// @goal 19 REQ-MB-013 : main route released for a siding request [config FEATURE_ROUTE]
// @goal 20 REQ-MB-013 : main route release refused: in use [config FEATURE_ROUTE]
// @goal 21 REQ-MB-011 REQ-MB-012 : siding route set, points reversed [config FEATURE_ROUTE]
// @goal 22 REQ-MB-011 : siding route refused: points in use [config FEATURE_ROUTE]
// @goal 23 REQ-MB-011 REQ-MB-013 : main route set again, points normal [config FEATURE_ROUTE]
// @goal 24 REQ-MB-011 : main route re-set refused: points in use [config FEATURE_ROUTE]
// @goal 25 REQ-MB-014 : possession requested [config FEATURE_POSS]
// @goal 26 REQ-MB-014 : possession confirmed active [config FEATURE_POSS]
// @goal 27 REQ-MB-014 : possession confirmation held back by a train or its authority [config FEATURE_POSS]
// @goal 28 REQ-MB-014 : possession cancelled [config FEATURE_POSS]
// @goal 29 REQ-MB-017 : radio channel in the next cell secured [config FEATURE_RADIO]
// @goal 30 REQ-MB-023 : neighbouring system accepts trains over the boundary [config FEATURE_RADIO]

#ifdef TRAPS
#include "mb_goals.pml"
#endif
