# starman_show: the 1995 paper's Table 4 and Figures 13-14. Mr. Star-Man cartwheels, jumps and
# shuffles, three enhanced (robust) sense-based BSR controllers run one after another; Figure 5's
# search moves the two switch points to make the total below as large as it can.
figure starman

# The phases in time order: the BSR search whose best controller runs (results/bsr/NAME/, best
# seed), the guessed duration in 0.01 s ticks (Table 4's: 159, 90, 100; ours are longer).
phase cartwheel controller=starman_cartwheel_robust ticks=215
phase jump      controller=starman_jump_robust      ticks=150
phase shuffle   controller=starman_shuffle_robust   ticks=100

# Each phase's credit. dcm_x: how far the centre of mass moved right during the phase (m);
# dtime: the phase's duration (ticks); 'a ?= b' is 1 when a == b and falls to 0 as they differ
# (exp(-((a - b) / w)^2), w = 20 % of b: 43 ticks for 215), so a phase is paid for keeping
# near its guessed duration. max_t(min_i(y_i(t))): the highest the lowest rod endpoint gets,
# the height cleared by the jump (m).
score cartwheel = dcm_x * (dtime ?= 215)
score jump      = max_t(min_i(y_i(t))) * (dtime ?= 150)
score shuffle   = dcm_x * (dtime ?= 100)

# The search maximises the product: no phase may be sacrificed to another.
total = (1.0 + cartwheel) * (1.0 + jump) * (1.0 + shuffle)

# Figure 5: Q = 16 transition-point arrays, G = 16 generations, H = 4 mutations each
# (16 x 16 x 4 = 1,024 simulations), random seed 1.
search q=16 g=16 h=4 seed=1
