/*
 * railproof — radio telegram safety layer (D5 §6.3, §6.4; EN 50159 defences).
 *
 * What is modelled. One endpoint R (the ground control unit or the on-board unit: their
 * logic is identical, only their outputs' names differ) runs the receiver checks of spec/design/tg.md §4 in the
 * same order as cpp/runtime/tg/src/endpoint.cpp, its link supervision (§5) and its sending
 * rule (§5, REQ-TG-008/-012). Its peer is abstracted to the peer's guarantee (below).
 * Between them a channel loses, duplicates, re-orders, delays and corrupts telegrams, and
 * an attacker without the link key injects forged or misrouted ones.
 *
 * Compositional argument (assume-guarantee, spec/design/tg.md §9). Both
 * endpoints run the same logic. The peer is modelled by its guarantee PG:
 *   PG1 it sends one telegram per tick, sequence numbers +1 modulo M;
 *   PG2 its echo is absent or names a sequence number that R sent at most
 *       E_MAX = A_MAX + T_ECHO ticks earlier (any such one, chosen nondeterministically).
 * PG1 is R's own sending rule; PG2 is asserted of R's own sending in this model
 * (assertion "R_GUARANTEE_ECHO_AGE" below). Since R satisfies PG and the peer is an
 * instance of R, the closed system of two endpoints is covered: every behaviour of the
 * real peer is a behaviour of the abstract one (PG over-approximates it), and the
 * guarantee refers only to the past, so circular reasoning is sound by induction on time.
 *
 * Bounds (spec/parameters/tg.yaml model_bounds, via tg_params.pml): sequence
 * numbers modulo M, window W, history H, turnaround T_TA, link timeout T_LINK, echo
 * validity T_ECHO in ticks of model_tick_ms; channel capacity CAP; channel age at most
 * A_MAX ticks (ASM-011). Counters saturate, so the search is exhaustive over unbounded
 * runs, including any number of sequence-number wrap-arounds (the initial sequence
 * numbers sit just below the wrap).
 *
 * Ghost variables (suffix _g, prefix v_) hold true ages; R never reads them.
 *
 * Annotations read by testgen:
 *   // @property <ltl name> <REQ ids> : text
 *   // @goal <K> <REQ ids> : label          (coverage goal K, trap property [] !g[K])
 *   // @mutant <NAME> violates <ltl name> | assert:<label> : text
 *   // @assert <label> <REQ ids> : text     (on the line before an assert(...))
 *   // @variant <DEFINE> <param>=<model bound> : text   (a boundary variant: every default
 *      property is verified in it too, and it supplies vectors for goals unreachable in
 *      the main configuration; the vector header carries the overridden parameter; without
 *      <param>=<bound> an environment variant, e.g. models/br.pml REALISABLE)
 */
#include "tg_params.pml"

#ifdef MUTANT_SEQ_WIDTH_8
#define M 8
#else
#define M MODEL_SEQ_MODULUS
#endif
#ifdef VARIANT_NARROW_WINDOW
#define W MODEL_NARROW_SEQ_WINDOW   /* boundary variant: the edge W + 1 becomes reachable */
#else
#define W MODEL_SEQ_WINDOW
#endif
#define H MODEL_HISTORY_DEPTH
#define T_TA MODEL_TURNAROUND_TICKS
#define T_LINK MODEL_LINK_TICKS
#define T_ECHO MODEL_ECHO_TICKS
#define A_MAX MODEL_MAX_DELAY_TICKS
#define CAP MODEL_CHANNEL_CAPACITY
#define E_MAX (A_MAX + T_ECHO)
/* TICKS below enumerates echo ages 0..5: keep E_MAX == 5 or extend the list */
#define NONE 255

#define INIT_OWN MODEL_INIT_OWN_SEQ
#define INIT_PEER MODEL_INIT_PEER_SEQ
#ifdef MUTANT_ECHO_NEVER_EXPIRES
#define PEER_AGE_CAP (E_MAX + 1)   /* the mutant needs the true age beyond T_ECHO */
#else
#define PEER_AGE_CAP (T_ECHO + 1)
#endif
#define STALEPEER 254   /* peer number known but expired: no decision reads it (below) */

#define L_NONE 0
#define L_UP 1
#define L_LOST 2

#define V_ACCEPT 0
#define V_INTEGRITY 1
#define V_ADDRESS 2
#define V_AUTH 3
#define V_REPEATED 4
#define V_SEQUENCE 5
#define V_NO_ECHO 6
#define V_UNKNOWN_ECHO 7
#define V_STALE 8

/* delivery modes chosen by the channel / attacker */
#define D_INTACT 0   /* deliver and remove */
#define D_DUP 1      /* deliver a copy, keep the original in flight (repetition) */
#define D_CORRUPT 2  /* deliver with symbol errors beyond the code's radius, remove */
#define D_FORGE 3    /* attacker injects the header without the key */
#define D_MISADDR 4  /* telegram with a wrong identifier (other train / attacker) */

#define CAPAGE (T_TA + 1)  /* ghost ages only matter up to "> T_TA" */
#define SAT(x, cap) if :: (x) < (cap) -> x++ :: else -> skip fi

typedef Msg {
  bool busy;
  byte seq;
  byte echo;    /* NONE: echo flag clear */
  byte age;     /* ticks in flight (ASM-011: at most A_MAX) */
  byte eage_g;  /* ghost: true age of R's telegram named by echo, capped at CAPAGE */
}
Msg q[CAP];     /* telegrams in flight towards R */

/* R: the endpoint under verification */
byte next;        /* next own sequence number */
byte sent;        /* own telegrams sent, saturating at H */
byte peer;        /* last in-sequence peer sequence number, NONE before the first */
byte peer_age;    /* ticks since peer was updated, saturating at PEER_AGE_CAP */
byte since;       /* ticks since the last acceptance, saturating at T_LINK + 1 */
byte link;
bit eb = 1;       /* on-board output: emergency brake demand */
bit abnormal = 1; /* ground output: train tracking abnormal */
byte peer_rx_age_g;  /* ghost: age at receipt of the telegram that set peer */
byte last_acc_g;     /* ghost: true send age of the last accepted telegram, capped */

/* abstract peer */
byte pnext;       /* peer's next sequence number (PG1) */
byte boot;        /* ticks since start, saturating at E_MAX + 1 */

/* violation flags (ghost), one per property */
bit v_repeat, v_reorder, v_corrupt, v_masq, v_insert, v_stale, v_turnaround, v_timeout;

/* scratch, reset after every step so that it never distinguishes states */
byte echo_out, slot, dd, k, verdict, gap, ea;

#ifdef TRAPS
#define NGOALS 20
bit g[NGOALS];
byte gi;
#define GOAL(x) g[x] = 1
#define CLEAR_GOALS for (gi : 0 .. NGOALS - 1) { g[gi] = 0 }; gi = 0
#include "tg_goals.pml"
#else
#define GOAL(x) skip
#define CLEAR_GOALS skip
#endif

#define SCRATCH_RESET echo_out = 0; slot = 0; dd = 0; k = 0; verdict = 0; gap = 0; ea = 0

/* Symmetry reduction: the channel is a set (any slot may be delivered next), so the two
   slots are kept in a canonical order after every step: occupied before free, older
   before younger, then by echo and ghost age. Slot positions are never observable. */
Msg tmp;
#define SWAP_SLOTS tmp.busy = q[0].busy; tmp.seq = q[0].seq; tmp.echo = q[0].echo; \
  tmp.age = q[0].age; tmp.eage_g = q[0].eage_g; \
  q[0].busy = q[1].busy; q[0].seq = q[1].seq; q[0].echo = q[1].echo; \
  q[0].age = q[1].age; q[0].eage_g = q[1].eage_g; \
  q[1].busy = tmp.busy; q[1].seq = tmp.seq; q[1].echo = tmp.echo; \
  q[1].age = tmp.age; q[1].eage_g = tmp.eage_g; \
  tmp.busy = 0; tmp.seq = 0; tmp.echo = 0; tmp.age = 0; tmp.eage_g = 0
inline canonical() {
  if
  :: !q[0].busy && q[1].busy -> SWAP_SLOTS
  :: q[0].busy && q[1].busy &&
     (q[0].age < q[1].age ||
      (q[0].age == q[1].age && (q[0].echo < q[1].echo ||
        (q[0].echo == q[1].echo && q[0].eage_g < q[1].eage_g)))) -> SWAP_SLOTS
  :: else -> skip
  fi;
  if
  :: !q[1].busy -> q[1].seq = 0; q[1].echo = 0; q[1].age = 0; q[1].eage_g = 0
  :: else -> skip
  fi;
  if
  :: !q[0].busy -> q[0].seq = 0; q[0].echo = 0; q[0].age = 0; q[0].eage_g = 0
  :: else -> skip
  fi
}

/* outputs derived from the link state (REQ-TG-014, REQ-TG-015) */
inline outputs() {
#ifdef MUTANT_EB_ONLY_WHEN_LOST
  eb = (link == L_LOST);
#else
  eb = (link != L_UP);
#endif
  abnormal = (link != L_UP)
}

/* ------------------------------------------------------------------ tick ---------- */
inline age_channel() {
  for (slot : 0 .. CAP - 1) {
    if
    :: q[slot].busy ->
       q[slot].age++;
       SAT(q[slot].eage_g, CAPAGE);
       if
       :: q[slot].age > A_MAX -> q[slot].busy = 0     /* ASM-011 */
       :: else -> skip
       fi
    :: else -> skip
    fi
  };
  slot = 0
}

inline supervise() {
  SAT(since, T_LINK + 1);
  SAT(peer_age, PEER_AGE_CAP);
  SAT(last_acc_g, A_MAX + 1);
  /* Dead-value reduction: once the echo has expired the peer number is read by no
     decision (the sequence check runs only while UP, and UP implies peer_age <= since
     <= T_LINK <= T_ECHO), so its value is forgotten to keep the state space small. The
     C++ keeps the number; no output differs. */
#ifndef MUTANT_ECHO_NEVER_EXPIRES
  if
  :: peer != NONE && peer_age > T_ECHO -> peer = STALEPEER
  :: else -> skip
  fi;
#endif
  if
#ifndef MUTANT_NO_LINK_TIMEOUT
  :: link == L_UP && since > T_LINK -> link = L_LOST; GOAL(16)     /* link lost */
#endif
  :: else -> skip
  fi;
  if
  :: link == L_UP && since == T_LINK -> GOAL(17)                   /* still up at T_LINK */
  :: else -> skip
  fi
}

/* R's sending rule (REQ-TG-008, REQ-TG-012) and its guarantee PG2 */
inline r_send() {
  if
#ifdef MUTANT_ECHO_NEVER_EXPIRES
  :: peer < M -> echo_out = peer
#else
  :: peer != NONE && peer_age <= T_ECHO -> echo_out = peer
#endif
  :: else -> echo_out = NONE
  fi;
  /* R's guarantee PG2: what R echoes was sent at most E_MAX ticks ago */
  // @assert R_GUARANTEE_ECHO_AGE REQ-TG-012 : R echoes only numbers sent at most E_MAX ticks ago (PG2)
  assert(echo_out == NONE || peer_rx_age_g + peer_age <= E_MAX);
  printf("@OUT tx seq=%d echo=%d link=%d eb=%d abnormal=%d\n", next, echo_out, link, eb, abnormal);
  if
  :: echo_out == NONE && peer != NONE -> GOAL(18)                   /* echo expired */
  :: else -> skip
  fi;
  next = (next + 1) % M;
  SAT(sent, H)
}

/* the abstract peer sends one telegram (PG1) echoing R's telegram of age ea (PG2) */
inline p_send() {
  if
  :: !q[0].busy -> slot = 0
  :: q[0].busy && !q[1].busy -> slot = 1
  :: else -> slot = NONE                       /* channel full: the telegram is lost */
  fi;
  if
  :: slot != NONE ->
     q[slot].busy = 1;
     q[slot].seq = pnext;
     q[slot].age = 0;
     if
     :: ea == NONE -> q[slot].echo = NONE; q[slot].eage_g = CAPAGE
     :: else -> q[slot].echo = (next + 2 * M - 1 - ea) % M;        /* after r_send */
                q[slot].eage_g = (ea < CAPAGE -> ea : CAPAGE)
     fi
  :: else -> skip
  fi;
  pnext = (pnext + 1) % M
}

inline tick() {
  CLEAR_GOALS;
  printf("@IN tick\n");
  age_channel();
  supervise();
  outputs();
  /* REQ-TG-013: never up after more than T_LINK ticks without acceptance */
  if
  :: link == L_UP && since > T_LINK -> v_timeout = 1
  :: else -> skip
  fi;
  SAT(boot, E_MAX + 1);
  r_send();
  p_send();
  canonical();
  SCRATCH_RESET
}

/* ---------------------------------------------------------------- receive --------- */
inline receive(s, mode) {
  CLEAR_GOALS;
  printf("@IN rx seq=%d echo=%d mode=%d\n", q[s].seq, q[s].echo, mode);
  gap = 0;
  if
#ifndef MUTANT_NO_INTEGRITY_CHECK
  :: mode == D_CORRUPT -> verdict = V_INTEGRITY                  /* CheckBlockDecoding / CheckFrameCrc */
#endif
#ifndef MUTANT_NO_ADDRESS_CHECK
  :: mode == D_MISADDR -> verdict = V_ADDRESS                    /* CheckAddressing */
#endif
#ifndef MUTANT_NO_AUTH_CHECK
  :: mode == D_FORGE -> verdict = V_AUTH                         /* CheckAuthenticity */
#endif
  :: else ->
     verdict = V_ACCEPT;
     if
     :: link == L_UP ->                                          /* CheckSequenceNumber */
        // @assert LIVE_PEER_WHEN_UP REQ-TG-004 : the sequence check never reads a forgotten peer number
        assert(peer < M);
        dd = (q[s].seq + M - peer) % M;
        if
#ifndef MUTANT_NO_REPEAT_CHECK
        :: dd == 0 -> verdict = V_REPEATED
#endif
#ifndef MUTANT_NO_WINDOW_CHECK
        :: dd > W -> verdict = V_SEQUENCE
#endif
        :: else -> gap = (dd > 0 -> dd - 1 : 0)
        fi
     :: else -> skip
     fi;
     if
     :: verdict == V_ACCEPT ->
        if
        :: peer < M && q[s].seq < peer -> GOAL(13)          /* peer number wrapped */
        :: else -> skip
        fi;
        peer = q[s].seq;                                         /* in sequence (REQ-TG-012) */
        peer_age = 0;
        peer_rx_age_g = q[s].age;
        if                                                       /* CheckEcho, CheckTurnaround */
        :: q[s].echo == NONE -> verdict = V_NO_ECHO
        :: else ->
           k = (next + 2 * M - 1 - q[s].echo) % M;
           if
#ifndef MUTANT_ECHO_UNCHECKED
           :: k >= sent || k >= H -> verdict = V_UNKNOWN_ECHO
#ifndef MUTANT_NO_TURNAROUND_CHECK
           :: k < sent && k < H && k > T_TA -> verdict = V_STALE
#endif
#endif
           :: else -> skip
           fi
        fi
     :: else -> skip
     fi
  fi;
  if
  :: verdict == V_ACCEPT ->
     if :: mode == D_CORRUPT -> v_corrupt = 1 :: else -> skip fi;
     if :: mode == D_FORGE -> v_masq = 1 :: else -> skip fi;
     if :: mode == D_MISADDR -> v_insert = 1 :: else -> skip fi;
     if :: q[s].age > T_TA -> v_stale = 1 :: else -> skip fi;
     if :: q[s].eage_g > T_TA -> v_turnaround = 1 :: else -> skip fi;
     if
     :: q[s].age == last_acc_g -> v_repeat = 1        /* same peer tick: the same telegram */
     :: q[s].age > last_acc_g -> v_reorder = 1        /* sent before the last accepted one */
     :: else -> skip
     fi;
     last_acc_g = q[s].age;
     if
     :: link == L_NONE -> GOAL(0)
     :: link == L_UP && gap == 0 -> GOAL(1)
     :: link == L_UP && gap > 0 -> GOAL(2)
     :: else -> GOAL(3)                                          /* recovery from LOST */
     fi;
     if :: q[s].echo != NONE && k == T_TA -> GOAL(14) :: else -> skip fi;
     if :: link == L_UP && dd == W -> GOAL(15) :: else -> skip fi;
     if :: q[s].echo != NONE && q[s].echo > (next + M - 1) % M -> GOAL(19) :: else -> skip fi;
     since = 0;
     link = L_UP
  :: else -> skip
  fi;
  outputs();
  printf("@OUT rx verdict=%d gap=%d link=%d eb=%d abnormal=%d\n", verdict, gap, link, eb, abnormal);
  if
  :: verdict == V_INTEGRITY -> GOAL(4)
  :: verdict == V_ADDRESS -> GOAL(5)
  :: verdict == V_AUTH -> GOAL(6)
  :: verdict == V_REPEATED -> GOAL(7)
  :: verdict == V_SEQUENCE -> GOAL(8);
     if :: dd == W + 1 -> GOAL(12) :: else -> skip fi
  :: verdict == V_NO_ECHO -> GOAL(9)
  :: verdict == V_UNKNOWN_ECHO -> GOAL(10)
  :: verdict == V_STALE -> GOAL(11)
  :: else -> skip
  fi;
  if
  :: mode == D_INTACT || mode == D_CORRUPT -> q[s].busy = 0
  :: else -> skip
  fi;
  canonical();
  SCRATCH_RESET
}

inline init_state() {
  next = INIT_OWN % M;
  pnext = INIT_PEER % M;
  peer = NONE;
  peer_age = T_ECHO + 1;
  since = T_LINK + 1;
  last_acc_g = A_MAX + 1;
  outputs()
}

/* One do-option per choice of the peer's echo (PG2), each a single d_step, so that no
   intermediate states are stored. TICK(a): the peer echoes R's telegram of age a
   (NONE: no echo); only telegrams R has actually sent can be named (a <= boot). */
#define TICK(a) :: CAN_TICK && (a == NONE || a <= boot) -> d_step { ea = a; tick() }

#ifdef HEALTHY
/* REQ-TG-016: every telegram is delivered intact within the tick it was sent in, and the
   peer echoes R's telegram of the previous tick (a perfect round trip). */
#define CAN_TICK (!q[0].busy && !q[1].busy)
#define TICKS \
  :: CAN_TICK && boot == 0 -> d_step { ea = NONE; tick() } \
  :: CAN_TICK && boot > 0 -> d_step { ea = 1; tick() }
#define DELIVER(S) :: q[S].busy -> d_step { receive(S, D_INTACT) }
#else
#define CAN_TICK true
#define TICKS TICK(NONE) TICK(0) TICK(1) TICK(2) TICK(3) TICK(4) TICK(5)
#define DELIVER(S) \
  :: q[S].busy -> d_step { receive(S, D_INTACT) } \
  :: q[S].busy -> d_step { receive(S, D_DUP) } \
  :: q[S].busy -> d_step { receive(S, D_CORRUPT) } \
  :: q[S].busy -> d_step { receive(S, D_FORGE) } \
  :: q[S].busy -> d_step { receive(S, D_MISADDR) } \
  :: q[S].busy -> d_step { CLEAR_GOALS; q[S].busy = 0; canonical() }
#endif

active proctype env() {
  d_step { init_state() };
  do
  TICKS
  DELIVER(0)
  DELIVER(1)
  od
}

/* ------------------------------------------------------- coverage goals ---------- */
// @goal 0 REQ-TG-012 : ACCEPT while link NONE (bootstrap)
// @goal 1 REQ-TG-008 : ACCEPT while link UP, no gap
// @goal 2 REQ-TG-002 : ACCEPT while link UP after deleted telegrams (gap reported)
// @goal 3 REQ-TG-013 : ACCEPT while link LOST (recovery)
// @goal 4 REQ-TG-005 : REJ_INTEGRITY
// @goal 5 REQ-TG-003 : REJ_ADDRESS
// @goal 6 REQ-TG-007 : REJ_AUTH
// @goal 7 REQ-TG-001 : REJ_REPEATED
// @goal 8 REQ-TG-004 : REJ_SEQUENCE
// @goal 9 REQ-TG-012 : REJ_NO_ECHO
// @goal 10 REQ-TG-008 : REJ_UNKNOWN_ECHO
// @goal 11 REQ-TG-006 REQ-TG-009 : REJ_STALE
// @goal 12 REQ-TG-004 : REJ_SEQUENCE at the window edge (advance W+1)
// @goal 13 REQ-TG-004 REQ-TG-017 : in-sequence across the peer's wrap-around
// @goal 14 REQ-TG-006 REQ-TG-009 : ACCEPT at the turnaround boundary (echo age = T_TA)
// @goal 15 REQ-TG-004 : ACCEPT at the window edge (advance = W)
// @goal 16 REQ-TG-013 REQ-TG-014 REQ-TG-015 : link UP -> LOST at the timeout
// @goal 17 REQ-TG-013 : link still UP at elapsed = T_LINK (timeout boundary)
// @goal 18 REQ-TG-012 : echo expired: sent without echo although a peer number is known
// @goal 19 REQ-TG-008 REQ-TG-017 : ACCEPT echoing a number sent before R's own wrap-around

/* ------------------------------------------------------------- properties --------- */
// @property REQ_TG_001_repetition REQ-TG-001 : no telegram is accepted twice
ltl REQ_TG_001_repetition { [] !v_repeat }
// @property REQ_TG_004_resequencing REQ-TG-004 REQ-TG-002 : accepted telegrams are in sending order
ltl REQ_TG_004_resequencing { [] !v_reorder }
// @property REQ_TG_005_corruption REQ-TG-005 : no corrupted telegram is accepted
ltl REQ_TG_005_corruption { [] !v_corrupt }
// @property REQ_TG_007_masquerade REQ-TG-007 : no telegram without the link key is accepted
ltl REQ_TG_007_masquerade { [] !v_masq }
// @property REQ_TG_003_insertion REQ-TG-003 : no misaddressed telegram is accepted
ltl REQ_TG_003_insertion { [] !v_insert }
// @property REQ_TG_006_delay REQ-TG-006 : no accepted telegram is older than T_TA
ltl REQ_TG_006_delay { [] !v_stale }
// @property REQ_TG_009_turnaround REQ-TG-009 REQ-TG-008 REQ-TG-012 REQ-TG-017 : the echoed telegram of an accepted telegram is at most T_TA old (no sequence aliasing)
ltl REQ_TG_009_turnaround { [] !v_turnaround }
// @property REQ_TG_013_link_timeout REQ-TG-013 REQ-TG-002 : the link is never up after more than T_LINK without acceptance
ltl REQ_TG_013_link_timeout { [] !v_timeout }
// @property REQ_TG_014_onboard_reaction REQ-TG-014 : the on-board unit demands the emergency brake whenever its link is not up
ltl REQ_TG_014_onboard_reaction { [] (link != 1 -> eb) }
// @property REQ_TG_015_ground_reaction REQ-TG-015 : the ground marks the train tracking abnormal whenever its link is not up
ltl REQ_TG_015_ground_reaction { [] (link != 1 -> abnormal) }
#ifdef HEALTHY
// @property REQ_TG_016_availability REQ-TG-016 : on a healthy channel the link is up from the third tick on [config HEALTHY]
ltl REQ_TG_016_availability { [] (boot >= 3 -> link == 1) }
#endif

/* --------------------------------------------------------------- variants --------- */
// @variant VARIANT_NARROW_WINDOW seq_window=narrow_seq_window : sequence window below T_TA + T_LINK, so that the window edge W + 1 (goal G12) is reachable

/* ---------------------------------------------------------------- mutants --------- */
// @mutant MUTANT_NO_TURNAROUND_CHECK violates REQ_TG_009_turnaround : echo found but its age is not compared with T_TA
// @mutant MUTANT_ECHO_UNCHECKED violates REQ_TG_009_turnaround : echo not verified at all
// @mutant MUTANT_NO_REPEAT_CHECK violates REQ_TG_001_repetition : sequence difference 0 accepted
// @mutant MUTANT_NO_WINDOW_CHECK violates REQ_TG_004_resequencing : sequence window not enforced
// @mutant MUTANT_NO_AUTH_CHECK violates REQ_TG_007_masquerade : authentication tag not verified
// @mutant MUTANT_NO_ADDRESS_CHECK violates REQ_TG_003_insertion : identifiers not compared
// @mutant MUTANT_NO_INTEGRITY_CHECK violates REQ_TG_005_corruption : RS/CRC result ignored
// @mutant MUTANT_NO_LINK_TIMEOUT violates REQ_TG_013_link_timeout : link never declared lost
// @mutant MUTANT_EB_ONLY_WHEN_LOST violates REQ_TG_014_onboard_reaction : no emergency brake before the first acceptance
// @mutant MUTANT_SEQ_WIDTH_8 violates REQ_TG_009_turnaround : sequence numbers modulo 8 alias within the echo age bound
// @mutant MUTANT_ECHO_NEVER_EXPIRES violates assert:R_GUARANTEE_ECHO_AGE : echo sent however old its peer update
