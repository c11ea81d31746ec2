/* The general 6R method (Raghavan-Roth, Manocha-Canny) in C, in derive_ik_runtime.h after
   derive/c/runtime.c, for the arms that define its tables (DK_RR_SPLIT_COUNT); it reads them
   (templates/general_arm.c.j2). The Python solver's routines (derive/runtime/general.py) step
   for step: per split, the 14 x 9 / 14 x 8 matrices of the pose, the left null space of Q, the
   12 x 12 quadratic matrix polynomial in a Moebius-mapped half-angle of theta3, its 24 x 24
   companion matrix's eigenvalues but the 2r known ones (deflated), by Hessenberg reduction and
   Francis double-shift QR, the null vector of each real root, theta1 and theta2 by back-
   substitution, theta6, and Levenberg-Marquardt steps on the forward kinematics; where the
   answer is in doubt, the fallback split and the rescue (the pose moved a little and polished
   back). No LAPACK. */
#include "runtime.c"

#define DK_RR_RANK_TOL (1e-10)
#define DK_RR_COND_LIMIT (100000000.0)
#define DK_RR_IMAG_TOL (1e-06)
#define DK_RR_IMAG_LOOSE (0.001)
#define DK_RR_CLUSTER_TOL (1e-06)
#define DK_RR_NULL2_TOL (1e-05)
#define DK_RR_GOOD (1e-10)
#define DK_RR_NEWTON_STEPS 10
#define DK_RR_NEWTON_REACH (0.5)
#define DK_RR_NEWTON_DONE (1e-11)
#define DK_RR_NEWTON_DONE_STEP (1e-08)
#define DK_RR_DAMPED_FROM (0.01)
#define DK_RR_ROWS 16 /* the most rows one pose gives */
/* the most seeds a nominal table's near misses give (three each for as many near misses as a
   pose has rows: the Python solver's _RR_SEEDS_EACH * MAX_SOLUTIONS) */
#define DK_RR_SEEDS (3 * DK_RR_ROWS)
#define DK_RR_OUT (DK_RR_ROWS + DK_RR_SEEDS) /* the rows, then a nominal table's seeds */
#define DK_RR_MAX 16  /* eigenvalues of one split */
#define DK_RR_CANDS (8 * DK_RR_MAX) /* candidates of one split, the extras' too */
#define DK_RR_PAIR_TOL (0.05)
#define DK_RR_PAIR_ANGLE (0.15)
#define DK_RR_SEARCH_FROM (0.1)
#define DK_RR_SEARCH_BAIL (0.3)
#define DK_RR_SINGULAR (1e-12)
#define DK_RR_SEARCH_STEPS 40
#define DK_RR_SEARCH_SLIDE (1.5)
#define DK_RR_MOTION_COUNT 2
#define DK_RR_PATH_COUNT 3
#define DK_RR_PATH_STEPS 2
/* a Newton step within this (radians) turns the joints' cos and sin by the angle-sum formulas
   and a few terms of the step's series (error d^6 / 720 ~ 1e-21), not by calling sincos */
#define DK_RR_SMALL (1e-3)
#define DK_RR_SAME (0.01)
#define DK_RR_SETTLED (1e-13)
/* an answer in doubt: the fallback split is tried (clusters on a perturbed table), and the
   rescue too (clusters on the arm's own table, a candidate Newton does not settle there, or
   no usable pencil) */
#define DK_RR_FALLBACK 2
#define DK_RR_RESCUE 1
/* where a perturbed table answered and a row found is within this of a singular configuration
   (Hadamard's ratio of its Jacobian), the rescue is tried too */
#define DK_RR_NEAR_SINGULAR (0.001)
/* a perturbed table's clusters ask for the fallback split unless the split's rows number its
   real eigenvalues and no complex one is within DK_RR_PAIR_DOUBT (1 + |y|) of the real line
   (the Python solver's _RR_PAIR_DOUBT); such a pair asks for it without clusters too */
#define DK_RR_PAIR_DOUBT (0.03)
/* on a nominal table (DK_SEED_TOL > 0), a candidate the steps leave within DK_SEED_TOL of the
   pose seeds the refinement, with the points this far each way along the direction the
   table's Jacobian nearly loses (a pair of the exact arm near a fold: dk_rr_fold_seeds) */
#define DK_RR_FOLD_STEP (0.001)
/* a merged pair's partner is looked for where J's least singular value is within this
   (dk_rr_fold_partners; the Python _RR_FOLD_NEAR says why) */
#define DK_RR_FOLD_NEAR (0.01)
#define DK_RR_SEARCH_COUNT 64

static const double DK_RR_MOEBIUS[3][4] = {{1.0, 0.3, -0.4, 1.0}, {1.0, -0.7, 0.5, 1.0}, {0.6, 1.0,
        -1.0, 0.8}};
static const double DK_RR_PATH[DK_RR_PATH_COUNT] = {0.3, 0.1, 0.03};
static const double DK_RR_H45[9][9] = {{-0.20715771404290617, 0.5927947440648359,
        0.20715771404290617, -1.0681999969191052, 3.056721043236494, 1.0681999969191052,
        0.20715771404290617, -0.5927947440648359, -0.20715771404290617}, {0.29639737203241795,
        0.41431542808581234, -0.29639737203241795, 1.528360521618247, 2.1363999938382103,
        -1.528360521618247, -0.29639737203241795, -0.41431542808581234, 0.29639737203241795},
        {-0.5340999984595526, 1.528360521618247, 0.5340999984595526, 0.41431542808581234,
        -1.1855894881296718, -0.41431542808581234, 0.5340999984595526, -1.528360521618247,
        -0.5340999984595526}, {0.7641802608091235, 1.0681999969191052, -0.7641802608091235,
        -0.5927947440648359, -0.8286308561716247, 0.5927947440648359, -0.7641802608091235,
        -1.0681999969191052, 0.7641802608091235}, {0.361615431964962, 0.0, 0.361615431964962,
        1.864654691212069, 0.0, 1.864654691212069, -0.361615431964962, -0.0, -0.361615431964962},
        {0.9323273456060345, 0.0, 0.9323273456060345, -0.723230863929924, -0.0, -0.723230863929924,
        -0.9323273456060345, -0.0, -0.9323273456060345}, {-0.5728674601004813, 1.639296035690959,
        0.5728674601004813, -0.0, 0.0, 0.0, -0.5728674601004813, 1.639296035690959,
        0.5728674601004813}, {0.8196480178454795, 1.1457349202009626, -0.8196480178454795, 0.0, 0.0,
        -0.0, 0.8196480178454795, 1.1457349202009626, -0.8196480178454795}, {1.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 1.0, 0.0, 1.0}};
/* x4 = tan((theta4 - DK_RR_SHIFT4) / 2), x5 likewise (the Python solver's _RR_SHIFT45) */
#define DK_RR_SHIFT4 (0.37)
#define DK_RR_SHIFT5 (-0.61)
static const double DK_RR_MIX[6][14] = {{0.831053977697249, 0.9900473146183112, 0.64314065170999,
        -0.032401674147217494, -0.6913872085223244, -0.9970837803306998, -0.7932848190961409,
        -0.1841286755130694, 0.5191145844484333, 0.957097725720417, 0.9060176352363181,
        0.39197550774272616, -0.3223604909348076, -0.8719748950976475}, {0.9900473146183112,
        -0.032401674147217494, -0.9970837803306998, -0.1841286755130694, 0.957097725720417,
        0.39197550774272616, -0.8719748950976475, -0.5813367556690181, 0.7457296853584616,
        0.7432821334878895, -0.5843158268289446, -0.870174289183519, 0.39534560504897837,
        0.9560289824265693}, {0.64314065170999, -0.9970837803306998, 0.5191145844484333,
        0.39197550774272616, -0.9760226149538952, 0.7457296853584616, 0.1067594209631354,
        -0.870174289183519, 0.9075631905615887, -0.187730865010247, -0.6887338553031781,
        0.9905566108870916, -0.46591295615435313, -0.44746305790115903}, {-0.032401674147217494,
        -0.1841286755130694, 0.39197550774272616, -0.5813367556690181, 0.7432821334878895,
        -0.870174289183519, 0.9560289824265693, -0.9967973016436514, 0.9905566108870916,
        -0.9376012214411736, 0.8404285120874396, -0.7036211525980088, 0.5336309848028128,
        -0.3384747534102578}, {-0.6913872085223244, 0.957097725720417, -0.9760226149538952,
        0.7432821334878895, -0.31888792310970165, -0.187730865010247, 0.6459436459222883,
        -0.9376012214411736, 0.987500301463081, -0.7827745135506544, 0.37621196990266487,
        0.12735603593086048, -0.5980855567720366, 0.9145999794700689}, {-0.9970837803306998,
        0.39197550774272616, 0.7457296853584616, -0.870174289183519, -0.187730865010247,
        0.9905566108870916, -0.44746305790115903, -0.7036211525980088, 0.8986597641266819,
        0.12735603593086048, -0.9803267573911277, 0.5012779986293977, 0.6588824957315815,
        -0.9237860638944368}};
static const int DK_RR_MONOMIAL_RULES[5][4] = {{0, 4, 1, 3}, {1, 5, 2, 4}, {3, 7, 4, 6}, {4, 8, 5,
        7}, {6, 10, 7, 9}};
static const double DK_RR_MOTIONS[DK_RR_MOTION_COUNT][4][4] = {{{0.999999996152,
        -6.400143989332459e-05, -5.999846390000934e-05, 3.6e-05}, {6.399855989334209e-05,
        0.9999999968000001, -4.800191991998833e-05, 4.8e-05}, {6.000153589999067e-05,
        4.799807992001167e-05, 0.999999997048, -8e-05}, {0.0, 0.0, 0.0, 1.0}}, {{0.9999999846080001,
        0.0001279942391467017, 0.00012000614319996266, 5.399999999999999e-05},
        {-0.0001280057591466317, 0.9999999872, 9.59923193600467e-05, 7.199999999999999e-05},
        {-0.00011999385520003735, -9.600767935995333e-05, 0.9999999881920001,
        -0.00011999999999999999}, {0.0, 0.0, 0.0, 1.0}}};
static const double DK_RR_SEARCH_STARTS[DK_RR_SEARCH_COUNT][6] = {{1.5843635225500652,
        -3.141301652582715, 1.657615914374258, 1.4305596408114196, -3.1340245664982334,
        1.803909481582232}, {-3.141301652582715, 1.4305596408114196, 1.803909481582232,
        -3.1169866509381823, 1.1100784607263365, 2.079203813915334}, {1.657615914374258,
        1.803909481582232, 1.9445848245339823, 2.079203813915334, 2.207347182751284,
        2.3286158322010078}, {1.4305596408114196, -3.1169866509381823, 2.079203813915334,
        0.7757788184272473, -2.952739844314279, 2.549040809456156}, {-3.1340245664982334,
        1.1100784607263365, 2.207347182751284, -2.952739844314279, 0.257557173670676,
        2.737734854751429}, {1.803909481582232, 2.079203813915334, 2.3286158322010078,
        2.549040809456156, 2.737734854751429, 2.892349069673648}, {1.2723003221697387,
        -3.0538708223418753, 2.4426320745396986, 0.08249005516504113, -2.542978486083067,
        3.0109587878481046}, {-3.1169866509381823, 0.7757788184272473, 2.549040809456156,
        -2.6419255771562393, -0.6148933315798525, 3.092087533541969}, {1.9445848245339823,
        2.3286158322010078, 2.6475106300024516, 2.892349069673648, 3.056282512736315,
        3.1347254011075547}, {1.1100784607263365, -2.952739844314279, 2.737734854751429,
        -0.6148933315798525, -1.9364469412877923, 3.1383416264748694}, {-3.0902409700010947,
        0.4318221377582462, 2.819432482947141, -2.1999719807039018, -1.4397647180002364,
        3.1028911942009834}, {2.079203813915334, 2.549040809456156, 2.892349069673648,
        3.092087533541969, 3.1383416264748694, 3.0288153978306127}, {0.9443992918082221,
        -2.8148526139946224, 2.9562575183163973, -1.281754776379049, -1.180077311745135,
        2.917036346592367}, {-3.0538708223418753, 0.08249005516504113, 3.0109587878481046,
        -1.6488166518066942, -2.1532302180870313, 2.768945486812339}, {2.207347182751284,
        2.737734854751429, 3.056282512736315, 3.1383416264748694, 2.9775626388599425,
        2.5863862809326066}, {0.7757788184272473, -2.6419255771562393, 3.092087533541969,
        -1.8849927553442205, -0.332395846863384, 2.371631259749373}, {-3.007989481740542,
        -0.2678688789081562, 3.1182623365563846, -1.0158177192452715, -2.7000834113662644,
        2.127353733529073}, {2.3286158322010078, 2.892349069673648, 3.1347254011075547,
        3.0288153978306127, 2.5863862809326066, 1.8565945141468783}, {0.6047422042034813,
        -2.4361113615717285, 3.141425453453899, -2.394663872397049, 0.5410056912153534,
        1.5627240624976668}, {-2.952739844314279, -0.6148933315798525, 3.1383416264748694,
        -0.332395846863384, -3.0380099780536662, 1.2494005323747024}, {2.4426320745396986,
        3.0109587878481046, 3.125483524660997, 2.768945486812339, 1.9950809349658025,
        0.9205242330938941}, {0.4318221377582462, -2.1999719807039018, 3.1028911942009834,
        -2.7854691830748624, 1.372545376598508, 0.5801890777212774}, {-2.8882939834715957,
        -0.9542634782104089, 3.0706349982589956, 0.36752541853501575, -3.1408618897895413,
        0.2326316212851653}, {2.549040809456156, 3.092087533541969, 3.0288153978306127,
        2.371631259749373, 1.2494005323747024, -0.11782167664525636}, {0.257557173670676,
        -1.9364469412877923, 2.9775626388599425, -3.0380099780536662, 2.0978804632014696,
        -0.46680830852970556}, {-2.8148526139946224, -1.281754776379049, 2.917036346592367,
        1.0492035368509198, -3.0006806876363177, -0.809984024158399}, {2.6475106300024516,
        3.1347254011075547, 2.847425028426307, 1.8565945141468783, 0.40704421325736884,
        -1.1430769086830164}, {0.08249005516504113, -1.6488166518066942, 2.768945486812339,
        -3.1397506920777625, 2.6608860875646507, -1.4619405602036917}, {-2.732644466918731,
        -1.5932905537699362, 2.681842144028197, 1.678801517366659, -2.628313290453677,
        -1.7626057049475843}, {2.737734854751429, 3.1383416264748694, 2.5863862809326066,
        1.2494005323747024, -0.46680830852970556, -2.0413296075237275}, {-0.09283397624756434,
        -1.3406615873597825, 2.482875192068846, -3.08564114163165, 3.0179980896494096,
        -2.2946426611861557}, {-2.6419255771562393, -1.8849927553442205, 2.371631259749373,
        2.2250675119591983, -2.0525726837289064, -2.519391578141195}, {2.819432482947141,
        3.1028911942009834, 2.2530009500056036, 0.5801890777212774, -1.30454021094791,
        -2.7127786422573186}, {-0.2678688789081562, -1.0158177192452715, 2.127353733529073,
        -2.878367204854847, 3.141583913514344, -2.872396535554245}, {-2.542978486083067,
        -2.1532302180870313, 1.9950809349658025, 2.6608860875646507, -1.3180084329489792,
        -2.996258304942407}, {2.892349069673648, 3.0288153978306127, 1.8565945141468783,
        -0.11782167664525636, -2.0413296075237275, -3.0828220961830253}, {-0.44206951164094216,
        -0.6783287640794202, 1.71232578305139, -2.5282175005048746, 3.0220807548527495,
        -3.1310103471751494}, {-2.4361113615717285, -2.394663872397049, 1.5627240624976668,
        2.964624176168882, -0.4814595343776316, -3.140223201648208}, {2.9562575183163973,
        2.917036346592367, 1.408255282746494, -0.809984024158399, -2.620165325014523,
        -3.110345976283929}, {-0.6148933315798525, -0.332395846863384, 1.2494005323747024,
        -2.0525726837289064, 2.6687355101497046, -3.0417505883155176}, {-2.3216570382113506,
        -2.606288307443143, 1.0866545599386177, 3.12120489234972, 0.3923436637961059,
        -2.9352909258330793}, {3.0109587878481046, 2.768945486812339, 0.9205242330938941,
        -1.4619405602036917, -2.996258304942407, -2.7922922184265713}, {-0.7858020839027097,
        0.017674795398651907, 0.7515269599707635, -1.4750427088699622, 2.1088892717906154,
        -2.614534540482497}, {-2.1999719807039018, -2.7854691830748624, 0.5801890777212774,
        3.12285591644838, 1.2357881560880102, -2.404230652488355}, {3.056282512736315,
        2.5863862809326066, 0.40704421325736884, -2.0413296075237275, -3.140507284268591,
        -2.1639984561803907}, {-0.9542634782104089, 0.36752541853501575, 0.2326316212851653,
        -0.8242948836694973, 1.385861733344202, -1.8968284064180703}, {-2.071435173665123,
        -2.9299760225763816, 0.05749450481169818, 2.969495295288429, 1.9836100281501974,
        -1.6060462854482966}, {3.092087533541969, 2.371631259749373, -0.11782167664525636,
        -2.519391578141195, -3.0417505883155176, -1.2952718029522208}, {-1.1197528463301156,
        0.7128010172129362, -0.29277090587517557, -0.13263088765775136, 0.5555992051745056,
        -0.968373537228927}, {-1.9364469412877923, -3.0380099780536662, -0.46680830852970556,
        2.6687355101497046, 2.5779444375989655, -0.6294207784164872}, {3.1182623365563846,
        2.127353733529073, -0.6393918501181661, -2.872396535554245, -2.707629797062612,
        -0.2826328732148781}, {-1.281754776379049, 1.0492035368509198, -0.809984024158399,
        0.5656166116142993, -0.3176543903031448, 0.06767329832296702}, {-1.7954277005436663,
        -3.1082262228260187, -0.9780535262252662, 2.235505610072509, 2.9728030706249258,
        0.41713706011334184}, {3.1347254011075547, 1.8565945141468783, -1.1430769086830164,
        -3.0828220961830253, -2.1639984561803907, 0.7614082225450518}, {-1.4397647180002364,
        1.372545376598508, -1.30454021094791, 1.2357881560880102, -1.166328574674909,
        1.0962012344451466}, {-1.6488166518066942, -3.1397506920777625, -1.4619405602036917,
        1.6913101669560104, 3.137632618455481, 1.4173485304134064}, {3.141425453453899,
        1.5627240624976668, -1.614787737584528, -3.140223201648208, -1.4529215854687192,
        1.7208524094480817}, {-1.5932905537699362, 1.678801517366659, -1.7626057049475843,
        1.844617915864792, -1.9247547713068902, 2.002934799068153}, {-1.497070410976207,
        -3.132190963378788, -1.9049340874801417, 1.0631618362786166, 3.059678926442822,
        2.2600842854590963}, {3.1383416264748694, 1.2494005323747024, -2.0413296075237275,
        -3.0417505883155176, -0.6294207784164872, 2.489099824202198}, {-1.7418541318832572,
        1.9641596260107044, -2.1713674651496464, 2.361884931262093, -2.534247598068824,
        2.6871305874681615}, {-1.3406615873597825, -3.08564114163165, -2.2946426611861557,
        0.3822405087589147, 2.744973883022019, 2.85171145164977}, {3.125483524660997,
        0.9205242330938941, -2.4107712585767485, -2.7922922184265713, 0.2427832499468753,
        2.9807936836769717}, {-1.8849927553442205, 2.2250675119591983, -2.519391578141195,
        2.761913214261249, -2.947645815536574, 3.0727704440255446}};
/* Python's a % m (the floored remainder) */
static double dk_pymod(double a, double m) { return a - m * floor(a / m); }

/* X := M^-1 X (n x n, m columns; row strides n and m) by Gaussian elimination with partial
   pivoting; 0 where M is singular */
static int dk_solve_into(const double *M, int n, double *X, int m)
{
    double A[24 * 24];
    int k, i, j, p;
    for (k = 0; k < n * n; k++) {
        A[k] = M[k];
    }
    for (k = 0; k < n; k++) {
        p = k;
        for (i = k + 1; i < n; i++) {
            if (fabs(A[i * n + k]) > fabs(A[p * n + k])) {
                p = i;
            }
        }
        if (A[p * n + k] == 0.0) {
            return 0;
        }
        if (p != k) {
            for (j = 0; j < n; j++) {
                double t = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = t;
            }
            for (j = 0; j < m; j++) {
                double t = X[k * m + j];
                X[k * m + j] = X[p * m + j];
                X[p * m + j] = t;
            }
        }
        for (i = k + 1; i < n; i++) {
            double f = A[i * n + k] / A[k * n + k];
            if (f != 0.0) {
                for (j = k + 1; j < n; j++) {
                    A[i * n + j] -= f * A[k * n + j];
                }
                for (j = 0; j < m; j++) {
                    X[i * m + j] -= f * X[k * m + j];
                }
            }
        }
    }
    for (k = n - 1; k >= 0; k--) {
        for (j = 0; j < m; j++) {
            double total = X[k * m + j];
            for (i = k + 1; i < n; i++) {
                total -= A[k * n + i] * X[i * m + j];
            }
            X[k * m + j] = total / A[k * n + k];
        }
    }
    return 1;
}

/* the ratio of the largest to the smallest pivot of M's (12 x 12) LU factorisation (HUGE_VAL
   where singular), with partial pivoting, or complete (complete set): its least pivot is then
   within a modest factor of M's least singular value, where partial pivoting's can be 1e2 to
   1e3 times above it (a pencil singular to roundings, pybullet's Panda's: 8e11 to 2e12 by
   partial pivots, 3e13 to 6e13 by singular values) */
static double dk_pivot_ratio(const double M[12][12], int complete)
{
    double A[12][12], big = 0.0, small = HUGE_VAL;
    int n = 12, k, i, j, p, q;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            A[i][j] = M[i][j];
        }
    }
    for (k = 0; k < n; k++) {
        p = q = k;
        for (i = k; i < n; i++) {
            for (j = k; j < (complete ? n : k + 1); j++) {
                if (fabs(A[i][j]) > fabs(A[p][q])) {
                    p = i;
                    q = j;
                }
            }
        }
        if (A[p][q] == 0.0) {
            return HUGE_VAL;
        }
        if (p != k) {
            for (j = 0; j < n; j++) {
                double t = A[k][j];
                A[k][j] = A[p][j];
                A[p][j] = t;
            }
        }
        if (q != k) {
            for (i = 0; i < n; i++) {
                double t = A[i][k];
                A[i][k] = A[i][q];
                A[i][q] = t;
            }
        }
        big = fmax(big, fabs(A[k][k]));
        small = fmin(small, fabs(A[k][k]));
        for (i = k + 1; i < n; i++) {
            double f = A[i][k] / A[k][k];
            for (j = k + 1; j < n; j++) {
                A[i][j] -= f * A[k][j];
            }
        }
    }
    return big / small;
}

/* rows spanning the left null space of Q (14 x 8) into N, six of them (fixed combinations
   where Q's rank is below 8): the last columns of the orthogonal factor of Q's QR
   factorisation with column pivoting; their number */
static int dk_null_left(const double Q[14][8], double N[14][14])
{
    double R[14][8], U[14][14], norms[8], v[14], top = 0.0;
    int m = 14, n = 8, rank = 0, k, i, j, p, free_rows;
    for (i = 0; i < m; i++) {
        for (j = 0; j < n; j++) {
            R[i][j] = Q[i][j];
        }
        for (j = 0; j < m; j++) {
            U[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (j = 0; j < n; j++) {
        double total = 0.0;
        for (i = 0; i < m; i++) {
            total += R[i][j] * R[i][j];
        }
        norms[j] = sqrt(total);
        top = fmax(top, norms[j]);
    }
    for (k = 0; k < n; k++) {
        double alpha = 0.0, vv = 0.0;
        p = k;
        for (j = k + 1; j < n; j++) {
            if (norms[j] > norms[p]) {
                p = j;
            }
        }
        if (norms[p] <= DK_RR_RANK_TOL * fmax(top, 1.0)) {
            break;
        }
        if (p != k) {
            double t;
            for (i = 0; i < m; i++) {
                t = R[i][k];
                R[i][k] = R[i][p];
                R[i][p] = t;
            }
            t = norms[k];
            norms[k] = norms[p];
            norms[p] = t;
        }
        for (i = k; i < m; i++) {
            alpha += R[i][k] * R[i][k];
        }
        alpha = sqrt(alpha);
        if (R[k][k] > 0.0) {
            alpha = -alpha;
        }
        for (i = 0; i < m; i++) {
            v[i] = i >= k ? R[i][k] : 0.0;
        }
        v[k] -= alpha;
        for (i = k; i < m; i++) {
            vv += v[i] * v[i];
        }
        if (vv == 0.0) {
            rank++;
            continue;
        }
        for (j = k; j < n; j++) {
            double f = 0.0;
            for (i = k; i < m; i++) {
                f += v[i] * R[i][j];
            }
            f = 2.0 * f / vv;
            for (i = k; i < m; i++) {
                R[i][j] -= f * v[i];
            }
        }
        for (i = 0; i < m; i++) { /* U := U H */
            double f = 0.0;
            for (j = k; j < m; j++) {
                f += U[i][j] * v[j];
            }
            f = 2.0 * f / vv;
            for (j = k; j < m; j++) {
                U[i][j] -= f * v[j];
            }
        }
        for (j = k + 1; j < n; j++) {
            double total = 0.0;
            for (i = k + 1; i < m; i++) {
                total += R[i][j] * R[i][j];
            }
            norms[j] = sqrt(total);
        }
        rank++;
    }
    free_rows = m - rank;
    if (free_rows <= 6) {
        for (i = 0; i < free_rows; i++) {
            for (j = 0; j < m; j++) {
                N[i][j] = U[j][rank + i];
            }
        }
        return free_rows;
    }
    for (i = 0; i < 6; i++) {
        for (j = 0; j < m; j++) {
            double total = 0.0;
            int r;
            for (r = 0; r < free_rows; r++) {
                total += DK_RR_MIX[i][r] * U[j][rank + r];
            }
            N[i][j] = total;
        }
    }
    return 6;
}

/* null vectors of S (12 x 12) into V's rows by Gaussian elimination with complete pivoting:
   their number; *plane: whether the null space looks two-dimensional */
static int dk_null_right(const double S[12][12], double V[3][12], int *plane)
{
    double A[12][12], x[12], top;
    int cols[12], n = 12, k, i, j, p, q, d, dims;
    for (i = 0; i < n; i++) {
        cols[i] = i;
        for (j = 0; j < n; j++) {
            A[i][j] = S[i][j];
        }
    }
    for (k = 0; k < n; k++) {
        double big = 0.0;
        p = k;
        q = k;
        for (i = k; i < n; i++) {
            for (j = k; j < n; j++) {
                if (fabs(A[i][j]) > big) {
                    big = fabs(A[i][j]);
                    p = i;
                    q = j;
                }
            }
        }
        if (p != k) {
            for (j = 0; j < n; j++) {
                double t = A[k][j];
                A[k][j] = A[p][j];
                A[p][j] = t;
            }
        }
        if (q != k) {
            int c;
            for (i = 0; i < n; i++) {
                double t = A[i][k];
                A[i][k] = A[i][q];
                A[i][q] = t;
            }
            c = cols[k];
            cols[k] = cols[q];
            cols[q] = c;
        }
        if (A[k][k] == 0.0) {
            continue;
        }
        for (i = k + 1; i < n; i++) {
            double f = A[i][k] / A[k][k];
            for (j = k + 1; j < n; j++) {
                A[i][j] -= f * A[k][j];
            }
            A[i][k] = 0.0;
        }
    }
    top = fabs(A[0][0]);
    *plane = fabs(A[n - 2][n - 2]) <= DK_RR_NULL2_TOL * top;
    dims = *plane ? 2 : 1;
    for (d = 0; d < dims; d++) {
        for (j = 0; j < n; j++) {
            x[j] = 0.0;
        }
        x[n - 1 - d] = 1.0;
        for (k = n - 1 - dims; k >= 0; k--) {
            double total = 0.0;
            for (j = k + 1; j < n; j++) {
                total += A[k][j] * x[j];
            }
            x[k] = A[k][k] != 0.0 ? -total / A[k][k] : 0.0;
        }
        for (j = 0; j < n; j++) {
            V[d][cols[j]] = x[j];
        }
    }
    return dims;
}

/* the (one or two) monomial vectors of the plane of V[0] and V[1] written to V[1] and V[2]
   (V[0] stays); their number */
static int dk_rr_unmix(double V[3][12])
{
    double v1[12], v2[12], bp = 0.0, bq = 0.0, br = 0.0, size = -1.0, root;
    int k, n = 0, s;
    for (k = 0; k < 12; k++) {
        v1[k] = V[0][k];
        v2[k] = V[1][k];
    }
    for (k = 0; k < 5; k++) {
        int i = DK_RR_MONOMIAL_RULES[k][0], j = DK_RR_MONOMIAL_RULES[k][1];
        int a = DK_RR_MONOMIAL_RULES[k][2], l = DK_RR_MONOMIAL_RULES[k][3];
        double p = v1[i] * v1[j] - v1[a] * v1[l];
        double q = v1[i] * v2[j] + v2[i] * v1[j] - v1[a] * v2[l] - v2[a] * v1[l];
        double r = v2[i] * v2[j] - v2[a] * v2[l];
        if (fabs(p) + fabs(q) + fabs(r) > size) {
            bp = p;
            bq = q;
            br = r;
            size = fabs(p) + fabs(q) + fabs(r);
        }
    }
    root = sqrt(fmax(bq * bq - 4.0 * bp * br, 0.0));
    for (s = 0; s < 2; s++) {
        double sign = s == 0 ? 1.0 : -1.0, u, w;
        double h = bq >= 0.0 ? -bq - sign * root : -bq + sign * root;
        if (fabs(bp) >= fabs(br)) {
            u = h;
            w = 2.0 * bp;
        } else {
            u = 2.0 * br;
            w = h;
        }
        if (fabs(u) + fabs(w) > 0.0) {
            for (k = 0; k < 12; k++) {
                V[1 + n][k] = u * v1[k] + w * v2[k];
            }
            n++;
        }
    }
    return n;
}

/* theta4 (step 3) or theta5 (step 1) from a null vector's entry ratios and the shifts */
static double dk_rr_ratio_angle(const double v[12], int step)
{
    double across = 0.0, low = 0.0, high = 0.0, shift;
    int i, j;
    for (i = 0; i < 4; i++) {
        for (j = 0; j < 3; j++) {
            int k = 3 * i + j;
            if ((step == 3 && i < 3) || (step == 1 && j < 2)) {
                double lo = v[k], hi = v[k + step];
                across += lo * hi;
                low += lo * lo;
                high += hi * hi;
            }
        }
    }
    shift = step == 3 ? DK_RR_SHIFT4 : DK_RR_SHIFT5;
    if (low >= high) {
        return 2.0 * atan2(across, low) + shift;
    }
    return 2.0 * atan2(high, across) + shift;
}

/* cos x and sin x at once, within 2^-53 of the library's for |x| <= 20 (50 million values),
   in 7 ns against its 13 (-O3 -march=native; its sincos saves and restores the rounding mode
   each call, and an eighth of a cobot's time went to it): x = k pi/2 + r, |r| <= pi/4 (pi/2
   split into DK_RR_PIO2_1 + DK_RR_PIO2_2 + DK_RR_PIO2_3, the first two rounded to 33 bits, so
   that k times them is exact for |k| < 2^20), then the Taylor series of sin r to r^17 and of
   cos r to r^16 (the next terms below 1e-18) and k's quadrant. Beyond 1e5 (and for a nan or an
   infinity), the library's */
#define DK_RR_TWO_OVER_PI (0.6366197723675814)
#define DK_RR_PIO2_1 (1.5707963267341256)
#define DK_RR_PIO2_2 (6.077100506303966e-11)
#define DK_RR_PIO2_3 (2.0222662487959506e-21)
static void dk_rr_sincos(double x, double *c, double *s)
{
    const double shifter = 6755399441055744.0; /* 1.5 2^52: adding it rounds to an integer */
    double k, r, r2, sr, cr;
    if (!(fabs(x) <= 1e5)) {
        *c = cos(x);
        *s = sin(x);
        return;
    }
    k = (x * DK_RR_TWO_OVER_PI + shifter) - shifter;
    r = ((x - k * DK_RR_PIO2_1) - k * DK_RR_PIO2_2) - k * DK_RR_PIO2_3;
    r2 = r * r;
    sr = r + r * r2 *
                 (-1.0 / 6.0 +
                  r2 * (1.0 / 120.0 +
                        r2 * (-1.0 / 5040.0 +
                              r2 * (1.0 / 362880.0 +
                                    r2 * (-1.0 / 39916800.0 +
                                          r2 * (1.0 / 6227020800.0 +
                                                r2 * (-1.0 / 1307674368000.0 +
                                                      r2 / 355687428096000.0)))))));
    cr = 1.0 + r2 * (-0.5 +
                     r2 * (1.0 / 24.0 +
                           r2 * (-1.0 / 720.0 +
                                 r2 * (1.0 / 40320.0 +
                                       r2 * (-1.0 / 3628800.0 +
                                             r2 * (1.0 / 479001600.0 +
                                                   r2 * (-1.0 / 87178291200.0 +
                                                         r2 / 20922789888000.0)))))));
    switch ((long)k & 3) { /* (x's quadrant: k mod 4, for a negative k too) */
    case 0:
        *c = cr;
        *s = sr;
        break;
    case 1:
        *c = -sr;
        *s = cr;
        break;
    case 2:
        *c = -cr;
        *s = -sr;
        break;
    default:
        *c = sr;
        *s = -cr;
        break;
    }
}

/* out := M A_i (standard DH row i: d, a, cos alpha, sin alpha) at the joint's cos ct and sin
   st (a sliding joint 3: ct, st of its fixed angle, d its value t); out may be M */
static void dk_rr_link_cs(double ct, double st, double t, const double rows[7][4], int i,
                          const double M[4][4], double out[4][4])
{
    const double d = i == 2 && rows[6][0] != 0.0 ? t : rows[i][0];
    const double a = rows[i][1], ca = rows[i][2], sa = rows[i][3];
    int r;
    for (r = 0; r < 4; r++) {
        const double m0 = M[r][0], m1 = M[r][1], m2 = M[r][2], m3 = M[r][3];
        const double x = m0 * ct + m1 * st, y = -m0 * st + m1 * ct;
        out[r][0] = x;
        out[r][1] = y * ca + m2 * sa;
        out[r][2] = -y * sa + m2 * ca;
        out[r][3] = m3 + x * a + m2 * d;
    }
}

/* M := M A_i(t) (standard DH row i: d, a, cos alpha, sin alpha) */
static void dk_rr_link(double t, const double rows[7][4], int i, double M[4][4])
{
    const double angle = i == 2 && rows[6][0] != 0.0 ? rows[6][1] : t; /* (a sliding joint 3:
                                                                          Rz(theta3) Tz(t) X3) */
    double ct, st;
    dk_rr_sincos(angle, &ct, &st);
    dk_rr_link_cs(ct, st, t, rows, i, (const double(*)[4])M, M);
}

/* x := A^-1 x for a 6 x 6 A by Gaussian elimination with partial pivoting (dk_solve_into's
   steps, its size fixed), |det A| into *size where size is not NULL; 0 where A is singular */
static int dk_solve6(const double M[6][6], double x[6], double *size)
{
    double A[6][6], det = 1.0;
    int k, i, j, p;
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            A[i][j] = M[i][j];
        }
    }
    for (k = 0; k < 6; k++) {
        p = k;
        for (i = k + 1; i < 6; i++) {
            if (fabs(A[i][k]) > fabs(A[p][k])) {
                p = i;
            }
        }
        if (A[p][k] == 0.0) {
            if (size != NULL) {
                *size = 0.0;
            }
            return 0;
        }
        det *= fabs(A[p][k]);
        if (p != k) {
            double t;
            for (j = 0; j < 6; j++) {
                t = A[k][j];
                A[k][j] = A[p][j];
                A[p][j] = t;
            }
            t = x[k];
            x[k] = x[p];
            x[p] = t;
        }
        for (i = k + 1; i < 6; i++) {
            const double f = A[i][k] / A[k][k];
            for (j = k + 1; j < 6; j++) {
                A[i][j] -= f * A[k][j];
            }
            x[i] -= f * x[k];
        }
    }
    for (k = 5; k >= 0; k--) {
        double total = x[k];
        for (i = k + 1; i < 6; i++) {
            total -= A[k][i] * x[i];
        }
        x[k] = total / A[k][k];
    }
    if (size != NULL) {
        *size = det;
    }
    return 1;
}

static void dk_eye4(double M[4][4])
{
    int r, c;
    for (r = 0; r < 4; r++) {
        for (c = 0; c < 4; c++) {
            M[r][c] = r == c ? 1.0 : 0.0;
        }
    }
}

/* (c, s) of unit length closest to solving system (4 x 3: c, s, right-hand side) in least
   squares, from the normal equations' 2 x 2 eigenproblem: one solution, or two where the
   system leaves a direction free; their number */
static int dk_unit_solutions(const double system[4][3], double cs[2][2])
{
    double g00 = 0.0, g01 = 0.0, g11 = 0.0, b0 = 0.0, b1 = 0.0, mean, spread, big, small;
    double angle, n0, n1, along, side;
    int r;
    for (r = 0; r < 4; r++) {
        g00 += system[r][0] * system[r][0];
        g01 += system[r][0] * system[r][1];
        g11 += system[r][1] * system[r][1];
        b0 += system[r][0] * system[r][2];
        b1 += system[r][1] * system[r][2];
    }
    mean = 0.5 * (g00 + g11);
    spread = hypot(0.5 * (g00 - g11), g01);
    big = mean + spread;
    small = mean - spread;
    cs[0][0] = cs[1][0] = 1.0;
    cs[0][1] = cs[1][1] = 0.0;
    if (big == 0.0) {
        return 1;
    }
    if (small > 1e-16 * big) {
        double det = g00 * g11 - g01 * g01;
        double c = (g11 * b0 - g01 * b1) / det, s = (g00 * b1 - g01 * b0) / det;
        double h = hypot(c, s);
        if (h == 0.0) {
            return 1;
        }
        cs[0][0] = cs[1][0] = c / h;
        cs[0][1] = cs[1][1] = s / h;
        return 1;
    }
    angle = (fabs(g01) > 0.0 || g00 != g11) ? 0.5 * atan2(2.0 * g01, g00 - g11) : 0.0;
    n0 = cos(angle);
    n1 = sin(angle);
    along = fmax(-1.0, fmin(1.0, (n0 * b0 + n1 * b1) / big));
    side = sqrt(1.0 - along * along);
    cs[0][0] = along * n0 - side * n1;
    cs[0][1] = along * n1 + side * n0;
    cs[1][0] = along * n0 + side * n1;
    cs[1][1] = along * n1 - side * n0;
    return 2;
}

/* theta1 and theta2 from theta3..theta5: their number of pairs, into t12 */
static int dk_rr_joints12(const double rows[7][4], const double F[4][4], double t3, double t4,
                          double t5, double t12[2][2])
{
    double M[4][4], gl[3], gp[3], fl[3], fp[3], system[4][3], cs[2][2];
    double d2 = rows[1][0], a2 = rows[1][1], ca2 = rows[1][2], sa2 = rows[1][3];
    double a1 = rows[0][1], ca1 = rows[0][2], sa1 = rows[0][3];
    int n, k, i;
    dk_eye4(M);
    dk_rr_link(t3, rows, 2, M);
    dk_rr_link(t4, rows, 3, M);
    dk_rr_link(t5, rows, 4, M);
    gl[0] = M[0][2];
    gl[1] = ca2 * M[1][2] - sa2 * M[2][2];
    gl[2] = sa2 * M[1][2] + ca2 * M[2][2];
    gp[0] = M[0][3] + a2;
    gp[1] = ca2 * M[1][3] - sa2 * M[2][3];
    gp[2] = sa2 * M[1][3] + ca2 * M[2][3] + d2;
    for (i = 0; i < 3; i++) {
        fl[i] = F[i][2];
        fp[i] = F[i][3];
    }
    system[0][0] = sa1 * gl[1];
    system[0][1] = sa1 * gl[0];
    system[0][2] = fl[2] - ca1 * gl[2];
    system[1][0] = sa1 * gp[1];
    system[1][1] = sa1 * gp[0];
    system[1][2] = fp[2] - ca1 * gp[2];
    system[2][0] = 2.0 * a1 * gp[0];
    system[2][1] = -2.0 * a1 * gp[1];
    system[2][2] = (fp[0] * fp[0] + fp[1] * fp[1] + fp[2] * fp[2]) -
                   (gp[0] * gp[0] + gp[1] * gp[1] + gp[2] * gp[2]) - a1 * a1;
    system[3][0] = a1 * gl[0];
    system[3][1] = -a1 * gl[1];
    system[3][2] = (fl[0] * fp[0] + fl[1] * fp[1] + fl[2] * fp[2]) -
                   (gl[0] * gp[0] + gl[1] * gp[1] + gl[2] * gp[2]);
    n = dk_unit_solutions((const double(*)[3])system, cs);
    for (k = 0; k < n; k++) {
        double c2 = cs[k][0], s2 = cs[k][1];
        double wl0 = c2 * gl[0] - s2 * gl[1], wl1 = s2 * gl[0] + c2 * gl[1], wl2 = gl[2];
        double wp0 = c2 * gp[0] - s2 * gp[1] + a1, wp1 = s2 * gp[0] + c2 * gp[1], wp2 = gp[2];
        double rl1 = ca1 * wl1 - sa1 * wl2, rp1 = ca1 * wp1 - sa1 * wp2;
        double across = wl0 * fl[1] - rl1 * fl[0] + wp0 * fp[1] - rp1 * fp[0];
        double along = wl0 * fl[0] + rl1 * fl[1] + wp0 * fp[0] + rp1 * fp[1];
        t12[k][0] = atan2(across, along);
        t12[k][1] = atan2(s2, c2);
    }
    return n;
}

static double dk_rr_theta6(const double rows[7][4], const double F[4][4], const double q[5])
{
    double M[4][4], r10, r00;
    int i;
    dk_eye4(M);
    for (i = 0; i < 5; i++) {
        dk_rr_link(q[i], rows, i, M);
    }
    r10 = M[0][1] * F[0][0] + M[1][1] * F[1][0] + M[2][1] * F[2][0];
    r00 = M[0][0] * F[0][0] + M[1][0] * F[1][0] + M[2][0] * F[2][0];
    return atan2(r10, r00);
}

/* the rows a share t of the way from the arm's (true) to the filled ones */
static void dk_rr_between(const double fill[7][4], const double truth[7][4], double t,
                          double out[7][4])
{
    int i;
    for (i = 0; i < 4; i++) {
        out[6][i] = truth[6][i];
    }
    for (i = 0; i < 6; i++) {
        double ca = truth[i][2] + t * (fill[i][2] - truth[i][2]);
        double sa = truth[i][3] + t * (fill[i][3] - truth[i][3]);
        double h = hypot(ca, sa);
        out[i][0] = truth[i][0] + t * (fill[i][0] - truth[i][0]);
        out[i][1] = truth[i][1] + t * (fill[i][1] - truth[i][1]);
        out[i][2] = ca / h;
        out[i][3] = sa / h;
    }
}

/* J := the geometric Jacobian of rows' chain at the frames F_0 .. F_6 of its joints (column i:
   z_i x (p - o_i) over z_i; a sliding joint 3: z_3 over 0) */
static void dk_rr_columns(const double rows[7][4], const double frames[7][4][4], double J[6][6])
{
    int i;
    for (i = 0; i < 6; i++) {
        const double z0 = frames[i][0][2], z1 = frames[i][1][2], z2 = frames[i][2][2];
        const double dx = frames[6][0][3] - frames[i][0][3];
        const double dy = frames[6][1][3] - frames[i][1][3];
        const double dz = frames[6][2][3] - frames[i][2][3];
        J[0][i] = z1 * dz - z2 * dy;
        J[1][i] = z2 * dx - z0 * dz;
        J[2][i] = z0 * dy - z1 * dx;
        J[3][i] = z0;
        J[4][i] = z1;
        J[5][i] = z2;
        if (i == 2 && rows[6][0] != 0.0) { /* a sliding joint 3 */
            J[0][i] = z0;
            J[1][i] = z1;
            J[2][i] = z2;
            J[3][i] = J[4][i] = J[5][i] = 0.0;
        }
    }
}

/* Steps on the forward kinematics of rows towards F from q (in place: the best point met; they
   stop where it is exact, its error beyond `reach` or its system singular): Newton's, or
   Levenberg-Marquardt's (damping |error|^2) where damped is set, `steps` + 1 of them (the
   last measured only where it is Newton's last, _RR_NEWTON_DONE); where track is set,
   `steps` Newton steps and q where they end (a continuation's corrector: not measured). The
   pose error at q (track: before the last step). Where turns is given, the joints' cos and
   sin at the q returned go there; where carried is set too, they are q's on entry (a
   candidate's walk goes on from where the last ended: a tenth of a cobot's time went to the
   sincos of each walk's start). */
static double dk_rr_turned_walk(const double rows[7][4], const double F[4][4], double q[6],
                                int damped, int steps, double reach, int track,
                                double turns[6][2], int carried)
{
    double cur[6], cs[6][2], best_cs[6][2], frames[7][4][4], J[6][6], normal[6][6], rhs[6];
    double step[6], best = HUGE_VAL;
    const int slider = rows[6][0] != 0.0 ? 2 : -1;
    int it, i, r, c, k;
    for (i = 0; i < 6; i++) {
        const double angle = i == slider ? rows[6][1] : q[i];
        cur[i] = q[i];
        if (turns != NULL && carried) {
            cs[i][0] = turns[i][0];
            cs[i][1] = turns[i][1];
        } else {
            dk_rr_sincos(angle, &cs[i][0], &cs[i][1]);
        }
        best_cs[i][0] = cs[i][0];
        best_cs[i][1] = cs[i][1];
    }
    dk_eye4(frames[0]);
    for (it = 0; it < steps + !track; it++) {
        double size = 0.0, longest = 0.0, mu = 0.0, scale;
        for (i = 0; i < 6; i++) {
            dk_rr_link_cs(cs[i][0], cs[i][1], cur[i], rows, i, (const double(*)[4])frames[i],
                          frames[i + 1]);
        }
        for (r = 0; r < 3; r++) {
            for (c = 0; c < 4; c++) {
                size = fmax(size, fabs(F[r][c] - frames[6][r][c]));
            }
        }
        if (size < best) {
            best = size;
            for (i = 0; i < 6; i++) {
                q[i] = cur[i];
                best_cs[i][0] = cs[i][0];
                best_cs[i][1] = cs[i][1];
            }
        }
        if (size <= 1e-15 || size > reach) {
            break;
        }
        for (r = 0; r < 3; r++) {
            int a = (r + 1) % 3, b = (r + 2) % 3;
            double total = 0.0;
            step[r] = F[r][3] - frames[6][r][3];
            for (k = 0; k < 3; k++) {
                total += frames[6][a][k] * F[b][k] - frames[6][b][k] * F[a][k];
            }
            step[3 + r] = 0.5 * total;
        }
        dk_rr_columns(rows, (const double(*)[4][4])frames, J);
        if (damped) { /* (J^T J + mu) step = J^T error, mu = |error|^2 */
            for (r = 0; r < 6; r++) {
                mu += step[r] * step[r];
            }
            for (r = 0; r < 6; r++) {
                rhs[r] = 0.0;
                for (k = 0; k < 6; k++) {
                    rhs[r] += J[k][r] * step[k];
                }
                for (c = 0; c < 6; c++) {
                    normal[r][c] = 0.0;
                    for (k = 0; k < 6; k++) {
                        normal[r][c] += J[k][r] * J[k][c];
                    }
                }
                normal[r][r] += mu;
            }
            for (r = 0; r < 6; r++) {
                step[r] = rhs[r];
            }
        }
        if (!dk_solve6(damped ? (const double(*)[6])normal : (const double(*)[6])J, step,
                       NULL)) {
            break;
        }
        for (i = 0; i < 6; i++) {
            longest = fmax(longest, fabs(step[i]));
        }
        scale = longest <= 0.5 ? 1.0 : 0.5 / longest;
        for (i = 0; i < 6; i++) {
            const double d = scale * step[i];
            cur[i] += d;
            if (i == slider) {
                continue;
            }
            if (fabs(d) <= DK_RR_SMALL) { /* (cos, sin) turned by d: its series to d^5 */
                const double d2 = d * d, cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0);
                const double sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0));
                const double c0 = cs[i][0], s0 = cs[i][1];
                cs[i][0] = c0 * cd - s0 * sd;
                cs[i][1] = s0 * cd + c0 * sd;
            } else {
                dk_rr_sincos(cur[i], &cs[i][0], &cs[i][1]);
            }
        }
        if (!damped && size <= DK_RR_NEWTON_DONE && longest <= DK_RR_NEWTON_DONE_STEP) {
            /* the last step, not measured (the Python solver's _RR_NEWTON_DONE) */
            for (i = 0; i < 6; i++) {
                q[i] = cur[i];
                best_cs[i][0] = cs[i][0];
                best_cs[i][1] = cs[i][1];
            }
            best = size;
            break;
        }
    }
    for (i = 0; i < 6 && turns != NULL; i++) {
        turns[i][0] = track ? cs[i][0] : best_cs[i][0];
        turns[i][1] = track ? cs[i][1] : best_cs[i][1];
    }
    for (i = 0; i < 6 && track; i++) {
        q[i] = cur[i];
    }
    return best;
}

/* dk_rr_turned_walk from q's own cos and sin */
static double dk_rr_walk(const double rows[7][4], const double F[4][4], double q[6], int damped,
                         int steps, double reach, int track)
{
    return dk_rr_turned_walk(rows, F, q, damped, steps, reach, track, NULL, 0);
}

/* dk_rr_walk's DK_RR_NEWTON_STEPS steps within DK_RR_NEWTON_REACH */
static double dk_rr_steps(const double rows[7][4], const double F[4][4], double q[6],
                          int damped)
{
    return dk_rr_walk(rows, F, q, damped, DK_RR_NEWTON_STEPS, DK_RR_NEWTON_REACH, 0);
}

/* Newton steps, then, where they do not reach DK_RR_GOOD (but end within DK_RR_DAMPED_FROM, or
   on a nominal table or an arm whose wrist flips), Levenberg-Marquardt steps from the best
   point met (the Python solver's _rr_newton_many): q in place, the pose error there; *used
   set where Newton did not settle it, damped steps or not */
static double dk_rr_newton(const double rows[7][4], const double F[4][4], double q[6],
                           int *used, int extra, double turns[6][2])
{
    double damped[6], damped_error;
    double error = dk_rr_turned_walk(rows, F, q, 0, DK_RR_NEWTON_STEPS, DK_RR_NEWTON_REACH, 0,
                                     turns, turns != NULL);
    int i;
    if (DK_RR_NEWTON_DONE < error && error <= DK_RR_GOOD) { /* (slowly: near a double root) */
        error = fmin(error, dk_rr_steps(rows, F, q, 0));
    }
    /* (an extra gets Newton's steps only, but on a nominal table: dk_rr_fold_seeds) */
    *used = error > DK_RR_GOOD && (!extra || DK_SEED_TOL > 0.0);
    if (!*used || (error > DK_RR_DAMPED_FROM && !(DK_SEED_TOL > 0.0) && !DK_RR_FLIPS[0] &&
                   !DK_RR_FLIPS[1])) {
        return error;
    }
    for (i = 0; i < 6; i++) {
        damped[i] = q[i];
    }
    damped_error = dk_rr_steps(rows, F, damped, 1);
    if (damped_error < error) { /* then Newton again: a regular solution settled exactly */
        for (i = 0; i < 6; i++) {
            q[i] = damped[i];
        }
        error = damped_error;
        damped_error = dk_rr_steps(rows, F, damped, 0);
        if (damped_error < error) {
            for (i = 0; i < 6; i++) {
                q[i] = damped[i];
            }
            error = damped_error;
        }
    }
    return error;
}

/* the eigenvalues (wr, wi) of M's leading n x n block (n <= 24): Householder reduction to upper
   Hessenberg form, then the Francis double-shift QR iteration with deflation (Golub and Van
   Loan, algorithms 7.4.2 and 7.5.2), eigenvalues only; 0 where it did not converge */
static int dk_eigenvalues(const double M[24][24], int n, double wr[24], double wi[24])
{
    double H[24][24], v[24];
    const double eps = 2.220446049250313e-16;
    int k, i, j, hi, lo, iterations = 0;
    for (i = 0; i < n; i++) {
        wr[i] = wi[i] = 0.0;
        for (j = 0; j < n; j++) {
            H[i][j] = M[i][j];
        }
    }
    for (k = 0; k < n - 2; k++) {
        double alpha = 0.0, vv = 0.0;
        for (i = k + 1; i < n; i++) {
            alpha += H[i][k] * H[i][k];
        }
        alpha = sqrt(alpha);
        if (alpha == 0.0) {
            continue;
        }
        if (H[k + 1][k] > 0.0) {
            alpha = -alpha;
        }
        for (i = k + 1; i < n; i++) {
            v[i] = H[i][k];
        }
        v[k + 1] -= alpha;
        for (i = k + 1; i < n; i++) {
            vv += v[i] * v[i];
        }
        if (vv == 0.0) {
            continue;
        }
        for (j = k; j < n; j++) {
            double f = 0.0;
            for (i = k + 1; i < n; i++) {
                f += v[i] * H[i][j];
            }
            f *= 2.0 / vv;
            for (i = k + 1; i < n; i++) {
                H[i][j] -= f * v[i];
            }
        }
        for (i = 0; i < n; i++) {
            double f = 0.0;
            for (j = k + 1; j < n; j++) {
                f += H[i][j] * v[j];
            }
            f *= 2.0 / vv;
            for (j = k + 1; j < n; j++) {
                H[i][j] -= f * v[j];
            }
        }
        for (i = k + 2; i < n; i++) {
            H[i][k] = 0.0;
        }
    }
    hi = n - 1;
    while (hi >= 0) {
        double trace, det, x, y, z, alpha;
        lo = hi;
        while (lo > 0) {
            double scale = fabs(H[lo - 1][lo - 1]) + fabs(H[lo][lo]);
            if (scale == 0.0) {
                for (i = 0; i <= hi; i++) {
                    for (j = 0; j <= hi; j++) {
                        scale = fmax(scale, fabs(H[i][j]));
                    }
                }
            }
            if (fabs(H[lo][lo - 1]) <= eps * scale) {
                H[lo][lo - 1] = 0.0;
                break;
            }
            lo--;
        }
        if (lo == hi) {
            wr[hi] = H[hi][hi];
            hi--;
            iterations = 0;
            continue;
        }
        if (lo == hi - 1) {
            double a = H[hi - 1][hi - 1], b = H[hi - 1][hi], c = H[hi][hi - 1], d = H[hi][hi];
            double half = 0.5 * (a - d), disc = half * half + b * c, mid = 0.5 * (a + d);
            if (disc >= 0.0) {
                double root = sqrt(disc), big = mid >= 0.0 ? mid + root : mid - root;
                wr[hi - 1] = big;
                wr[hi] = big != 0.0 ? (a * d - b * c) / big : mid - root;
            } else {
                double root = sqrt(-disc);
                wr[hi - 1] = wr[hi] = mid;
                wi[hi - 1] = root;
                wi[hi] = -root;
            }
            hi -= 2;
            iterations = 0;
            continue;
        }
        iterations++;
        if (iterations > 60) {
            return 0;
        }
        if (iterations % 10 == 0) {
            double s = fabs(H[hi][hi - 1]) + fabs(H[hi - 1][hi - 2]);
            trace = 1.5 * s;
            det = s * s;
        } else {
            trace = H[hi - 1][hi - 1] + H[hi][hi];
            det = H[hi - 1][hi - 1] * H[hi][hi] - H[hi - 1][hi] * H[hi][hi - 1];
        }
        x = H[lo][lo] * H[lo][lo] + H[lo][lo + 1] * H[lo + 1][lo] - trace * H[lo][lo] + det;
        y = H[lo + 1][lo] * (H[lo][lo] + H[lo + 1][lo + 1] - trace);
        z = H[lo + 1][lo] * H[lo + 2][lo + 1];
        for (k = lo; k < hi - 1; k++) {
            alpha = sqrt(x * x + y * y + z * z);
            if (alpha != 0.0) {
                double u0, u1, u2, uu;
                int first = lo > k - 1 ? lo : k - 1, last = k + 3 < hi ? k + 3 : hi;
                if (x > 0.0) {
                    alpha = -alpha;
                }
                u0 = x - alpha;
                u1 = y;
                u2 = z;
                uu = u0 * u0 + u1 * u1 + u2 * u2;
                for (j = first; j <= hi; j++) {
                    double f = 2.0 * (u0 * H[k][j] + u1 * H[k + 1][j] + u2 * H[k + 2][j]) / uu;
                    H[k][j] -= f * u0;
                    H[k + 1][j] -= f * u1;
                    H[k + 2][j] -= f * u2;
                }
                for (i = lo; i <= last; i++) {
                    double f = 2.0 * (u0 * H[i][k] + u1 * H[i][k + 1] + u2 * H[i][k + 2]) / uu;
                    H[i][k] -= f * u0;
                    H[i][k + 1] -= f * u1;
                    H[i][k + 2] -= f * u2;
                }
                if (k > lo) {
                    H[k + 1][k - 1] = 0.0;
                    H[k + 2][k - 1] = 0.0;
                }
            }
            x = H[k + 1][k];
            y = H[k + 2][k];
            if (k < hi - 2) {
                z = H[k + 3][k];
            }
        }
        k = hi - 1;
        alpha = sqrt(x * x + y * y);
        if (alpha != 0.0) {
            double u0, u1, uu;
            if (x > 0.0) {
                alpha = -alpha;
            }
            u0 = x - alpha;
            u1 = y;
            uu = u0 * u0 + u1 * u1;
            for (j = lo > k - 1 ? lo : k - 1; j <= hi; j++) {
                double f = 2.0 * (u0 * H[k][j] + u1 * H[k + 1][j]) / uu;
                H[k][j] -= f * u0;
                H[k + 1][j] -= f * u1;
            }
            for (i = lo; i <= hi; i++) {
                double f = 2.0 * (u0 * H[i][k] + u1 * H[i][k + 1]) / uu;
                H[i][k] -= f * u0;
                H[i][k + 1] -= f * u1;
            }
            if (k > lo) {
                H[k + 1][k - 1] = 0.0;
            }
        }
    }
    return 1;
}

/* the 12 x 12 matrices A, B, C of the pencil A y^2 + B y + C under the Moebius map m */
static void dk_rr_pencil(const double A6[6][9], const double B6[6][9], const double C6[6][9],
                         const double m[4], double out[3][12][12])
{
    double a = m[0], b = m[1], c = m[2], d = m[3];
    int i, j, k;
    for (k = 0; k < 3; k++) {
        for (i = 0; i < 12; i++) {
            for (j = 0; j < 12; j++) {
                out[k][i][j] = 0.0;
            }
        }
    }
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 9; j++) {
            double x = A6[i][j], y = B6[i][j], z = C6[i][j];
            double values[3];
            values[0] = a * a * x + a * c * y + c * c * z;
            values[1] = 2.0 * a * b * x + (a * d + b * c) * y + 2.0 * c * d * z;
            values[2] = b * b * x + b * d * y + d * d * z;
            for (k = 0; k < 3; k++) {
                out[k][i][j] = values[k];
                out[k][6 + i][3 + j] = values[k];
            }
        }
    }
}

/* x[0..n) sorted ascending in place (insertion sort) */
static void dk_sort_doubles(double *x, int n)
{
    int k, j;
    for (k = 1; k < n; k++) {
        double v = x[k];
        for (j = k - 1; j >= 0 && x[j] > v; j--) {
            x[j + 1] = x[j];
        }
        x[j + 1] = v;
    }
}

/* whether a root y is kept: any where joint 3 turns; where it slides, |d3| within reach */
static int dk_rr_within_reach(const double rows[7][4], const double *moebius, double y,
                              double reach)
{
    return rows[6][0] == 0.0 ||
           fabs(moebius[0] * y + moebius[1]) <= reach * fabs(moebius[2] * y + moebius[3]);
}

/* the value of y tried for side (-1 or +1) of a nearly real pair re +- i im (im > 0: two
   near-equal real roots that rounding, or a perturbed table's difference, split apart), in
   *y; 0 where the pair is not nearly real. Nearly real is judged by theta3's imaginary part,
   2 |det M| im / ((ma re + mb)^2 + (mc re + md)^2) to first order (M the Moebius map): within
   DK_RR_PAIR_ANGLE, the pair is tried at theta3's real part -+ that; a sliding joint 3 (x3 is
   d3) at re -+ im, within DK_RR_PAIR_TOL (1 + |y|) (the Python solver's _rr_pair_extras) */
static int dk_rr_pair_value(const double rows[7][4], const double *moebius, double re,
                            double im, int side, double *y)
{
    const double ma = moebius[0], mb = moebius[1], mc = moebius[2], md = moebius[3];
    const double num = ma * re + mb, den = mc * re + md;
    double spread, half;
    if (rows[6][0] != 0.0) {
        *y = re + side * im;
        return im <= DK_RR_PAIR_TOL * (1.0 + hypot(re, im));
    }
    spread = 2.0 * fabs(ma * md - mb * mc) * im / (num * num + den * den);
    if (!(spread <= DK_RR_PAIR_ANGLE)) {
        return 0;
    }
    half = tan((2.0 * atan2(num, den) + side * spread) / 2.0);
    *y = (md * half - mb) / (ma - mc * half);
    return isfinite(*y);
}

/* whether split k solves a perturbed table (the arm's own pencils are singular) */
static int dk_rr_perturbed(int k)
{
    int i, j;
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 4; j++) {
            if (DK_RR_FILL[k][i][j] != DK_RR_TRUE[k][i][j]) {
                return 1;
            }
        }
    }
    return 0;
}

/* split k's companion matrix K without its known eigenvalues (_rr_deflated in
   derive/runtime/general.py): K[o, o] - G K[p', o], p' the rows DK_RR_PIVOTS[k] and 12 more,
   o the others, G = [Re W[o] - (yr / yi) Im W[o], Im W[o] / yi] for W = [v; y+ v] (v the
   split's DK_RR_SPURIOUS vectors, y+ = (d i - b) / (a - c i) the image of x3 = i), moved to
   K's top left corner; its size */
static int dk_rr_deflate(double K[24][24], int k, const double *moebius)
{
    const int count = DK_RR_SPURIOUS_COUNT[k], r = count / 2;
    const double a = moebius[0], b = moebius[1], c = moebius[2], d = moebius[3];
    const double scale = 1.0 / (a * a + c * c);
    const double yr = (-b * a - d * c) * scale, yi = (d * a - b * c) * scale;
    double G[24][DK_RR_SPURIOUS_WIDTH], out[24][24];
    int p[DK_RR_SPURIOUS_WIDTH], o[24], taken[24] = {0}, n = 0, i, j, m;
    if (count == 0) {
        return 24;
    }
    for (j = 0; j < r; j++) {
        p[j] = DK_RR_PIVOTS[k][j];
        p[r + j] = DK_RR_PIVOTS[k][j] + 12;
        taken[p[j]] = taken[p[r + j]] = 1;
    }
    for (i = 0; i < 24; i++) {
        if (!taken[i]) {
            o[n++] = i;
        }
    }
    for (i = 0; i < n; i++) {
        const int row = o[i] % 12;
        for (j = 0; j < r; j++) {
            double vr = DK_RR_SPURIOUS[k][row][2 * j], vi = DK_RR_SPURIOUS[k][row][2 * j + 1];
            if (o[i] >= 12) {
                const double wr = yr * vr - yi * vi;
                vi = yr * vi + yi * vr;
                vr = wr;
            }
            G[i][j] = vr - (yr / yi) * vi;
            G[i][r + j] = vi / yi;
        }
    }
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            double total = K[o[i]][o[j]];
            for (m = 0; m < count; m++) {
                total -= G[i][m] * K[p[m]][o[j]];
            }
            out[i][j] = total;
        }
    }
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            K[i][j] = out[i][j];
        }
    }
    return n;
}

/* the pencil in x3 of a split's matrices (values: P0, Ps, Pc, Q as dk_rr_fill writes them):
   A6 x3^2 + B6 x3 + C6, Q's left null space times P's (the Python solver's _rr_pencil6); 0
   where Q's null space is empty */
static int dk_rr_pencil6(const double values[490], double A6[6][9], double B6[6][9],
                         double C6[6][9])
{
    double N[14][14];
    const double(*P0)[9] = (const double(*)[9])values;
    const double(*Ps)[9] = (const double(*)[9])(values + 126);
    const double(*Pc)[9] = (const double(*)[9])(values + 252);
    const double(*Q)[8] = (const double(*)[8])(values + 378);
    int rank_rows = dk_null_left(Q, N), i, m, r, col;
    if (rank_rows == 0) {
        return 0;
    }
    for (i = 0; i < 6; i++) {
        for (col = 0; col < 9; col++) {
            A6[i][col] = B6[i][col] = C6[i][col] = 0.0;
        }
    }
    for (i = 0; i < rank_rows && i < 6; i++) {
        for (m = 0; m < 9; m++) {
            double a = 0.0, b = 0.0, cc = 0.0;
            for (r = 0; r < 14; r++) {
                a += N[i][r] * (P0[r][m] - Pc[r][m]);
                b += N[i][r] * 2.0 * Ps[r][m];
                cc += N[i][r] * (P0[r][m] + Pc[r][m]);
            }
            for (col = 0; col < 9; col++) {
                double h = DK_RR_H45[m][col];
                if (h != 0.0) {
                    A6[i][col] += a * h;
                    B6[i][col] += b * h;
                    C6[i][col] += cc * h;
                }
            }
        }
    }
    return rank_rows;
}

/* the candidate joint vectors of one split: their count written to out, extra[c] set for
   those from nearly real pairs, or -1 where the pencil is singular (no usable one: the Python
   solver's None); *doubt: whether the answer is in doubt (clusters on the arm's own table, or
   no usable pencil); *reals: the real eigenvalues within reach, *pair: the least
   |Im y| / (1 + |y|) of the others (HUGE_VAL where none) */
static int dk_rr_candidates(const double values[490], const double F[4][4],
                            const double rows[7][4], double out[DK_RR_CANDS][6], int extra[],
                            int *doubt, double imag_tol, int split, int *reals_found,
                            double *pair)
{
    double A6[6][9], B6[6][9], C6[6][9], pencil[3][12][12], best_pencil[3][12][12];
    double K[24][24], rhs[12][24], wr[24], wi[24], reals[24], extras[48], V[3][12];
    double best = HUGE_VAL;
    /* a sliding joint 3: |d3| <= |p| + the other links' lengths (roots beyond are spurious) */
    double reach = fabs(F[0][3]) + fabs(F[1][3]) + fabs(F[2][3]);
    const double *moebius = DK_RR_MOEBIUS[0];
    int i, m, col, c, n_eig, n_real = 0, n_extra = 0, count = 0, start = 0;
    *doubt = DK_RR_RESCUE;
    *reals_found = 0;
    *pair = HUGE_VAL;
    for (i = 0; i < 6; i++) {
        reach += fabs(rows[i][0]) + fabs(rows[i][1]);
    }
    if (!dk_rr_pencil6(values, A6, B6, C6)) {
        return -1;
    }
    for (c = 0; c < 3; c++) {
        double ratio;
        dk_rr_pencil((const double(*)[9])A6, (const double(*)[9])B6, (const double(*)[9])C6,
                     DK_RR_MOEBIUS[c], pencil);
        ratio = dk_pivot_ratio((const double(*)[12])pencil[0], 0);
        if (ratio < best) {
            best = ratio;
            moebius = DK_RR_MOEBIUS[c];
            for (m = 0; m < 3; m++) {
                for (i = 0; i < 12; i++) {
                    for (col = 0; col < 12; col++) {
                        best_pencil[m][i][col] = pencil[m][i][col];
                    }
                }
            }
        }
        if (ratio < DK_RR_COND_LIMIT) {
            break;
        }
    }
    if (!(best < 1e16)) {
        return -1;
    }
    for (i = 0; i < 24; i++) {
        for (col = 0; col < 24; col++) {
            K[i][col] = 0.0;
        }
    }
    for (i = 0; i < 12; i++) {
        K[i][12 + i] = 1.0;
        for (col = 0; col < 12; col++) {
            rhs[i][col] = -best_pencil[2][i][col];
            rhs[i][12 + col] = -best_pencil[1][i][col];
        }
    }
    if (!dk_solve_into(&best_pencil[0][0][0], 12, &rhs[0][0], 24)) {
        return -1;
    }
    for (i = 0; i < 12; i++) {
        for (col = 0; col < 24; col++) {
            K[12 + i][col] = rhs[i][col];
        }
    }
    n_eig = dk_rr_deflate(K, split, moebius);
    if (!dk_eigenvalues((const double(*)[24])K, n_eig, wr, wi)) {
        return -1;
    }
    for (i = 0; i < n_eig; i++) {
        const double size = 1.0 + hypot(wr[i], wi[i]);
        int side;
        if (fabs(wi[i]) <= imag_tol * size) {
            if (dk_rr_within_reach(rows, moebius, wr[i], reach)) {
                reals[n_real++] = wr[i];
            }
        } else if (imag_tol * size < wi[i]) {
            *pair = fmin(*pair, wi[i] / size);
            for (side = -1; side <= 1; side += 2) { /* a nearly real pair (dk_rr_pair_value) */
                double y;
                if (dk_rr_pair_value(rows, moebius, wr[i], wi[i], side, &y) &&
                    dk_rr_within_reach(rows, moebius, y, reach)) {
                    extras[n_extra++] = y;
                }
            }
        }
    }
    *reals_found = n_real;
    dk_sort_doubles(reals, n_real);
    dk_sort_doubles(extras, n_extra);
    *doubt = 0;
    while (start < n_real + n_extra) {
        double y = 0.0, theta3, S[12][12];
        int stop = start + 1, clustered, nv, plane, v, is_extra = start >= n_real;
        if (is_extra) { /* (on their own: they put nothing in doubt) */
            y = extras[start - n_real];
        } else {
            while (stop < n_real && reals[stop] - reals[stop - 1] <=
                                        DK_RR_CLUSTER_TOL * (1.0 + fabs(reals[stop]))) {
                stop++;
            }
            for (i = start; i < stop; i++) {
                y += reals[i];
            }
            y /= (double)(stop - start);
        }
        clustered = stop - start > 1;
        start = stop;
        if (rows[6][0] != 0.0) { /* joint 3 slides: x3 is d3 */
            theta3 = (moebius[0] * y + moebius[1]) / (moebius[2] * y + moebius[3]);
        } else {
            theta3 = 2.0 * atan2(moebius[0] * y + moebius[1], moebius[2] * y + moebius[3]);
        }
        for (i = 0; i < 12; i++) {
            for (col = 0; col < 12; col++) {
                S[i][col] = best_pencil[0][i][col] * (y * y) + best_pencil[1][i][col] * y +
                            best_pencil[2][i][col];
            }
        }
        nv = dk_null_right((const double(*)[12])S, V, &plane);
        if (clustered || plane) {
            /* (a perturbed table's clusters are the arm's pairs sharing the eigen-joint's
               value, which its special geometry makes common: both come from the plane, and
               the partners and the search find one lost; they ask for the fallback only) */
            if (!is_extra) {
                *doubt |= dk_rr_perturbed(split) ? DK_RR_FALLBACK : DK_RR_RESCUE;
            }
            if (nv == 2) {
                nv = 1 + dk_rr_unmix(V);
            }
        }
        for (v = 0; v < nv; v++) {
            double t4 = dk_rr_ratio_angle(V[v], 3), t5 = dk_rr_ratio_angle(V[v], 1);
            double t12[2][2];
            int pairs = dk_rr_joints12(rows, F, theta3, t4, t5, t12), p;
            for (p = 0; p < pairs; p++) {
                double q5[5];
                if (count == DK_RR_CANDS) {
                    *doubt |= is_extra ? 0 : DK_RR_RESCUE;
                    return count;
                }
                extra[count] = is_extra;
                q5[0] = out[count][0] = t12[p][0];
                q5[1] = out[count][1] = t12[p][1];
                q5[2] = out[count][2] = theta3;
                q5[3] = out[count][3] = t4;
                q5[4] = out[count][4] = t5;
                out[count][5] = dk_rr_theta6(rows, F, q5);
                count++;
            }
        }
    }
    return count;
}

/* split k's joint values q as the arm's, into arm (a sliding joint 3 in the arm's lengths;
   the reversed chain's joint j is -q_{7-j}) */
static void dk_rr_arm(int k, const double q[6], double arm[6])
{
    int j;
    for (j = 0; j < 6; j++) {
        const double v = DK_RR_REVERSED[k] ? -q[5 - j] : q[j];
        arm[j] = j == (DK_RR_REVERSED[k] ? 3 : 2) && DK_RR_TRUE[k][6][0] != 0.0
                     ? v * DK_RR_LENGTH : v;
    }
}

/* the largest difference of two rows' joints, modulo 2 pi */
static double dk_rr_gap(const double a[6], const double b[6])
{
    double gap = 0.0;
    int j;
    for (j = 0; j < 6; j++) {
        gap = fmax(gap, fabs(dk_pymod(a[j] - b[j] + DK_PI, DK_TWO_PI) - DK_PI));
    }
    return gap;
}

/* whether split k's q lies within DK_RR_SAME of one of out[0..count) but not within the
   dedup's 1e-7: perhaps a copy of that row near a fold, not settled to rounding (the Python
   solver's _rr_unsettled_copy; _RR_SETTLED says why) */
static int dk_rr_unsettled_copy(int k, const double q[6], const double out[DK_RR_ROWS][6],
                                int count)
{
    double arm[6];
    int r;
    dk_rr_arm(k, q, arm);
    for (r = 0; r < count; r++) {
        const double gap = dk_rr_gap(arm, out[r]);
        if (gap <= DK_RR_SAME && gap > 1e-7) {
            return 1;
        }
    }
    return 0;
}

/* the index of the first row of out[0..count) within tol of split k's q (as the arm's values),
   or -1 */
static int dk_rr_index(int k, const double q[6], const double out[][6], int count,
                       double tol)
{
    double arm[6];
    int r;
    dk_rr_arm(k, q, arm);
    for (r = 0; r < count; r++) {
        if (dk_rr_gap(arm, out[r]) <= tol) {
            return r;
        }
    }
    return -1;
}

/* split k's joint values q (as the arm's) added to out[0..count) unless there already (within
   1e-7): the new count */
static int dk_rr_add(int k, const double q[6], double out[][6], int count)
{
    if (dk_rr_index(k, q, (const double(*)[6])out, count, 1e-7) >= 0) {
        return count;
    }
    dk_rr_arm(k, q, out[count]);
    return count + 1;
}

/* J = the geometric Jacobian of split k's own table at its values q (lengths in units of
   DK_RR_LENGTH) */
static void dk_rr_jacobian(int k, const double q[6], double J[6][6])
{
    double frames[7][4][4];
    const int slider = DK_RR_TRUE[k][6][0] != 0.0 ? 2 : -1;
    int i;
    dk_eye4(frames[0]);
    for (i = 0; i < 6; i++) {
        const double angle = i == slider ? DK_RR_TRUE[k][6][1] : q[i];
        double ct, st;
        dk_rr_sincos(angle, &ct, &st);
        dk_rr_link_cs(ct, st, q[i], DK_RR_TRUE[k], i, (const double(*)[4])frames[i],
                      frames[i + 1]);
    }
    dk_rr_columns(DK_RR_TRUE[k], (const double(*)[4][4])frames, J);
}

/* The seeds of split k's values q, which the steps left near the pose on a nominal table (the
   Python solver's _rr_fold_seeds): q, and q +- DK_RR_FOLD_STEP along the direction the
   table's Jacobian nearly loses there (two steps of inverse iteration on J^T J from (1, ...,
   1)), as the arm's values, added to seeds[0..n) where new and room is left: the new count */
static double dk_rr_lost_direction(int k, const double q[6], double v[6]);

static int dk_rr_fold_seeds(int k, const double q[6], double seeds[DK_RR_SEEDS][6], int n)
{
    double v[6], x[6];
    int i, h;
    (void)dk_rr_lost_direction(k, q, v);
    for (h = 0; h < 3 && n < DK_RR_SEEDS; h++) {
        const double step = h == 0 ? 0.0 : (h == 1 ? DK_RR_FOLD_STEP : -DK_RR_FOLD_STEP);
        for (i = 0; i < 6; i++) {
            x[i] = q[i] + step * v[i];
        }
        n = dk_rr_add(k, x, seeds, n);
    }
    return n;
}

/* The seeds of split k's near misses misses[0..n) on a nominal table (its values) added to
   seeds[0..n_seeds) (dk_rr_fold_seeds: new ones, while there is room): first those of each
   miss not within DK_RR_FOLD_STEP of a seed, then the others' (the Python solver's
   _rr_seed_misses says why); the new count */
static int dk_rr_seed_misses(int k, const double misses[][6], int n,
                             double seeds[DK_RR_SEEDS][6], int n_seeds)
{
    int late[DK_RR_CANDS], m;
    for (m = 0; m < n; m++) {
        late[m] = 0;
    }
    for (m = 0; m < n && n_seeds < DK_RR_SEEDS; m++) {
        late[m] = dk_rr_index(k, misses[m], (const double(*)[6])seeds, n_seeds,
                              DK_RR_FOLD_STEP) >= 0;
        if (!late[m]) {
            n_seeds = dk_rr_fold_seeds(k, misses[m], seeds, n_seeds);
        }
    }
    for (m = 0; m < n && n_seeds < DK_RR_SEEDS; m++) {
        if (late[m]) {
            n_seeds = dk_rr_fold_seeds(k, misses[m], seeds, n_seeds);
        }
    }
    return n_seeds;
}

/* v := the unit direction the Jacobian of split k's own table nearly loses at its values q
   (two steps of inverse iteration on J^T J from (1, ..., 1)); the least eigenvalue of J^T J
   that estimates (0 where J^T J is singular): the Python _rr_lost_direction */
static double dk_rr_lost_direction(int k, const double q[6], double v[6])
{
    double J[6][6], A[6][6], w[6], size, least = 0.0;
    int i, j, r, it;
    dk_rr_jacobian(k, q, J);
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            A[i][j] = 0.0;
            for (r = 0; r < 6; r++) {
                A[i][j] += J[r][i] * J[r][j];
            }
        }
        v[i] = 1.0 / sqrt(6.0);
    }
    for (it = 0; it < 2; it++) {
        for (i = 0; i < 6; i++) {
            w[i] = v[i];
        }
        if (!dk_solve6((const double(*)[6])A, w, NULL)) {
            least = 0.0;
            break; /* (singular: v is as good a direction as any) */
        }
        size = 0.0;
        for (i = 0; i < 6; i++) {
            size += w[i] * w[i];
        }
        size = sqrt(size);
        if (!(0.0 < size && size < HUGE_VAL)) {
            least = 0.0;
            break;
        }
        for (i = 0; i < 6; i++) {
            v[i] = w[i] / size;
        }
        least = 1.0 / size;
    }
    return least;
}

/* split k's rows that Newton's steps reach from q +- h along the direction its Jacobian
   nearly loses (dk_rr_lost_direction), h the gap between q and start, the candidate
   it came from (at least DK_RR_FOLD_STEP), added to out[count..] where new: the partner of a
   row two candidates of a nearly real pair both polished onto, where J's least singular value
   at q is within DK_RR_FOLD_NEAR, and not within DK_RR_SAME of a row (a copy of it: the Python
   _rr_split says why); the new count */
static int dk_rr_fold_partners(int k, const double F[4][4], const double q[6],
                               const double start[6], double out[DK_RR_ROWS][6], int count)
{
    static const double steps[2] = {1.0, -1.0};
    double v[6], x[6], a[6], b[6], h;
    int i, s;
    dk_rr_arm(k, start, a);
    dk_rr_arm(k, q, b);
    h = fmax(DK_RR_FOLD_STEP, dk_rr_gap(a, b));
    if (dk_rr_lost_direction(k, q, v) > DK_RR_FOLD_NEAR * DK_RR_FOLD_NEAR) {
        return count; /* (not near a fold: a complex pair's real row, alone) */
    }
    for (s = 0; s < 2 && count < DK_RR_ROWS; s++) {
        for (i = 0; i < 6; i++) {
            x[i] = q[i] + steps[s] * h * v[i];
        }
        /* (within DK_RR_SAME of a row: a copy of it) */
        if (dk_rr_steps(DK_RR_TRUE[k], F, x, 0) <= DK_RR_GOOD &&
            dk_rr_index(k, x, (const double(*)[6])out, count, DK_RR_SAME) < 0) {
            count = dk_rr_add(k, x, out, count);
        }
    }
    return count;
}

/* what the candidates that did not polish leave for a pose with no row (the Python solver's
   _RRLeads and its near rows): a singular pencil on the arm's own table, the rows (the arm's
   values) that stopped within DK_RR_SEARCH_FROM of the pose, where the search starts
   (dk_rr_search), and those within DK_RR_NEAR of it but extras', which the caller certifies.
   Before these, a pose with no row was handed to the Python solver (DK_UNSETTLED), which took
   0.07-0.4 s for each pose out of reach (a new user's manocha_canny path). */
#define DK_RR_NEAR (1e-07)
typedef struct {
    double rows[DK_RR_ROWS][6], near[DK_RR_ROWS][6];
    /* clear: the first split at the pose gave no real eigenvalue and none within
       DK_RR_PAIR_DOUBT (a nominal table's seeds' window, if wider) of real (dk_general's
       early answer) */
    int n, n_near, singular, clear;
} dk_rr_leads;

/* split k's polished candidates for the target F (found from the pose `moved`) added to
   out[count..] where new, until DK_RR_ROWS (a candidate within DK_RR_SAME of a row out had
   before is not polished: that row again); the new count; *doubt as dk_rr_candidates'; on a
   nominal table, the seeds of candidates left within DK_SEED_TOL added to seeds[0..*n_seeds)
   (dk_rr_fold_seeds) */
static int dk_rr_split(int k, const double F[4][4], const double moved[4][4],
                       double out[DK_RR_ROWS][6], int count, int *doubt, double imag_tol,
                       double seeds[DK_RR_SEEDS][6], int *n_seeds, dk_rr_leads *leads)
{
    double values[490], cands[DK_RR_CANDS][6], between[7][4], misses[DK_RR_CANDS][6];
    const int known = count;
    double pair;
    int extra[DK_RR_CANDS], perturbed = dk_rr_perturbed(k), damped = 0, reals, n, c, i, j, r;
    int n_misses = 0;
    int paired[DK_RR_ROWS]; /* (per row of out: an extra candidate's, first) */
    for (r = 0; r < DK_RR_ROWS; r++) {
        paired[r] = 0;
    }
    for (i = 0; i < 490; i++) {
        values[i] = 0.0;
    }
    dk_rr_fill(k, moved[0][2], moved[1][2], moved[2][2], moved[0][3], moved[1][3], moved[2][3],
               values);
    n = dk_rr_candidates(values, moved, DK_RR_FILL[k], cands, extra, doubt, imag_tol, k, &reals,
                         &pair);
    if (k == 0 && moved == F) { /* (the first split at the pose itself) */
        leads->clear = n >= 0 && reals == 0 && pair > fmax(DK_RR_PAIR_DOUBT, sqrt(DK_SEED_TOL));
    }
    if (n < 0) { /* (a singular pencil) */
        leads->singular |= !perturbed;
        n = 0;
    } else if (perturbed && pair <= DK_RR_PAIR_DOUBT && k + 1 < DK_RR_SPLIT_COUNT) {
        /* (a pair nearly real, clusters or not: perhaps two of the arm's solutions the
           table's difference made complex, which only a plane brings out; _rr_split says
           why; the last split's has no split to ask for) */
        *doubt |= DK_RR_FALLBACK;
    }
    for (c = 0; c < n; c++) {
        double q[6], arm[6], turns[6][2], error;
        int seen = 0;
        dk_rr_arm(k, cands[c], arm);
        /* (on a perturbed table, a row this split found too: _rr_split says why) */
        for (r = 0; r < (perturbed ? count : known) && !seen; r++) {
            seen = dk_rr_gap(arm, out[r]) <= DK_RR_SAME;
        }
        if (seen) {
            continue;
        }
        for (j = 0; j < 6; j++) {
            q[j] = cands[c][j];
        }
        if (perturbed) {
            for (i = 0; i < (int)(sizeof DK_RR_PATH / sizeof DK_RR_PATH[0]); i++) {
                dk_rr_between(DK_RR_FILL[k], DK_RR_TRUE[k], DK_RR_PATH[i], between);
                /* (Newton only on the way, each walk from where the last ended) */
                dk_rr_turned_walk((const double(*)[4])between, F, q, 0, DK_RR_PATH_STEPS,
                                  DK_RR_NEWTON_REACH, 1, turns, i > 0);
            }
        }
        error = dk_rr_newton(DK_RR_TRUE[k], F, q, &damped, extra[c], perturbed ? turns : NULL);
        if (damped && !perturbed && !extra[c]) { /* Newton alone did not settle it */
            *doubt = DK_RR_RESCUE;
        }
        if (error > DK_RR_GOOD) {
            if (error <= DK_RR_SEARCH_FROM && leads->n < DK_RR_ROWS) {
                leads->n = dk_rr_add(k, q, leads->rows, leads->n);
            }
            if (error <= DK_RR_NEAR && !extra[c] && leads->n_near < DK_RR_ROWS) {
                leads->n_near = dk_rr_add(k, q, leads->near, leads->n_near);
            }
            if (error <= DK_SEED_TOL) { /* (a nominal table's near miss: 0 elsewhere) */
                for (j = 0; j < 6; j++) {
                    misses[n_misses][j] = q[j];
                }
                n_misses++;
            }
            if (!perturbed && !extra[c]) {
                *doubt = DK_RR_RESCUE;
            }
            continue;
        }
        if (error > DK_RR_SETTLED &&
            dk_rr_unsettled_copy(k, q, (const double(*)[6])out, count)) {
            error = fmin(error, dk_rr_walk(DK_RR_TRUE[k], F, q, 0, 2, DK_RR_NEWTON_REACH, 0));
        }
        r = dk_rr_index(k, q, (const double(*)[6])out, count, 1e-7);
        if (r < 0) {
            count = dk_rr_add(k, q, out, count);
            paired[count - 1] = extra[c];
        } else if (extra[c] && r >= known && paired[r]) { /* (a nearly real pair's
            candidates polished onto one row: the row across the fold, _rr_split says why) */
            count = dk_rr_fold_partners(k, F, q, cands[c], out, count);
        }
        if (count == DK_RR_ROWS) {
            *n_seeds = dk_rr_seed_misses(k, (const double(*)[6])misses, n_misses, seeds, *n_seeds);
            return count;
        }
    }
    *n_seeds = dk_rr_seed_misses(k, (const double(*)[6])misses, n_misses, seeds, *n_seeds);
    if (*doubt == DK_RR_FALLBACK && count - known >= reals && pair > DK_RR_PAIR_DOUBT) {
        *doubt = 0; /* (every real root gave its row, and no pair is nearly real) */
    }
    return count;
}

/* whether a row (the arm's values) is within DK_RR_NEAR_SINGULAR of a singular configuration:
   |det J| over the product of J's column norms (Hadamard's ratio: 1 where the columns are
   orthogonal, 0 where J is singular), J the geometric Jacobian of split 0's chain (lengths in
   units of DK_RR_LENGTH) */
static int dk_rr_near_singular(const double row[6])
{
    double q[6], J[6][6], x[6] = {0.0}, ratio = 0.0;
    int i, r;
    for (i = 0; i < 6; i++) { /* the arm's values as split 0's */
        q[i] = DK_RR_REVERSED[0] ? -row[5 - i] : row[i];
    }
    if (DK_RR_TRUE[0][6][0] != 0.0) {
        q[2] /= DK_RR_LENGTH;
    }
    dk_rr_jacobian(0, q, J);
    for (i = 0; i < 6; i++) {
        double norm = 0.0;
        for (r = 0; r < 6; r++) {
            norm += J[r][i] * J[r][i];
        }
        if (!(norm > 0.0)) {
            return 1;
        }
        for (r = 0; r < 6; r++) {
            J[r][i] /= sqrt(norm);
        }
    }
    dk_solve6((const double(*)[6])J, x, &ratio); /* (|det J|, the columns of unit length) */
    return ratio <= DK_RR_NEAR_SINGULAR;
}

/* The wrist-flip partners of out[0..count) (the Python solver's _rr_partners): each row with
   the three joints at an end that is a spherical wrist (DK_RR_FLIPS: never the end with a
   sliding joint) turned as its flip, (t1 + pi, -t2, t3 + pi), polished by Newton's steps on
   split 0's frame and the arm's own table, added where they reach DK_RR_GOOD and are new.
   The new count. */
static int dk_rr_partners(const double F[4][4], double out[DK_RR_ROWS][6], int count)
{
    const int rows = count;
    const int slider = DK_RR_TRUE[0][6][0] != 0.0 ? (DK_RR_REVERSED[0] ? 3 : 2) : -1;
    int r, first, j;
    for (r = 0; r < rows && count < DK_RR_ROWS; r++) {
        for (first = 0; first <= 3 && count < DK_RR_ROWS; first += 3) {
            double p[6], q[6];
            if (!DK_RR_FLIPS[first / 3]) {
                continue;
            }
            for (j = 0; j < 6; j++) {
                p[j] = out[r][j];
            }
            p[first] += DK_PI;
            p[first + 1] = -p[first + 1];
            p[first + 2] += DK_PI;
            for (j = 0; j < 6; j++) { /* the arm's values as split 0's */
                q[j] = DK_RR_REVERSED[0] ? -p[5 - j] : p[j];
            }
            if (slider >= 0) {
                q[2] /= DK_RR_LENGTH;
            }
            if (dk_rr_steps(DK_RR_TRUE[0], F, q, 0) <= DK_RR_GOOD) {
                count = dk_rr_add(0, q, out, count);
            }
        }
    }
    return count;
}

/* An odd count (real solutions pair up where the pose is regular): the one missed looked for
   (the Python solver's _rr_search) by damped steps on split 0's frame, without a reach, from
   the rows found (or, for a pose with no row, the leads': starts[0..given)) and from
   DK_RR_SEARCH_STARTS (a sliding joint 3's within +-DK_RR_SEARCH_SLIDE
   of the arm's size); none where no row came within DK_RR_SEARCH_BAIL after a quarter of the
   steps; then Newton's steps from those within DK_RR_SEARCH_FROM. The new count. */
static int dk_rr_search(const double F[4][4], const double starts[DK_RR_ROWS][6], int given,
                        double out[DK_RR_ROWS][6], int count)
{
    double Q[DK_RR_ROWS + DK_RR_SEARCH_COUNT][6], least = HUGE_VAL;
    const int first = DK_RR_SEARCH_STEPS / 4, n = given + DK_RR_SEARCH_COUNT;
    const int slides = DK_RR_TRUE[0][6][0] != 0.0;
    int r, j;
    for (r = 0; r < n; r++) {
        for (j = 0; j < 6; j++) {
            if (r < given) { /* the arm's values as split 0's */
                Q[r][j] = DK_RR_REVERSED[0] ? -starts[r][5 - j] : starts[r][j];
            } else {
                Q[r][j] = DK_RR_SEARCH_STARTS[r - given][j];
            }
        }
        if (slides) {
            Q[r][2] = r < given ? Q[r][2] / DK_RR_LENGTH
                                : Q[r][2] * (DK_RR_SEARCH_SLIDE / DK_PI);
        }
        least = fmin(least, dk_rr_walk(DK_RR_TRUE[0], F, Q[r], 1, first, HUGE_VAL, 0));
    }
    if (!(least <= DK_RR_SEARCH_BAIL)) {
        return count;
    }
    for (r = 0; r < n && count < DK_RR_ROWS; r++) {
        const double error = dk_rr_walk(DK_RR_TRUE[0], F, Q[r], 1, DK_RR_SEARCH_STEPS - first,
                                        HUGE_VAL, 0);
        if (error <= DK_RR_SEARCH_FROM && dk_rr_steps(DK_RR_TRUE[0], F, Q[r], 0) <= DK_RR_GOOD) {
            count = dk_rr_add(0, Q[r], out, count);
        }
    }
    return count;
}

/* whether split k's pencil at the target F is singular to roundings (the Python solver's
   _rr_singular): the leading matrix under every Moebius map, the pencil at three values of
   x3, has an LU factor (complete pivoting) whose least pivot is within DK_RR_SINGULAR of its
   largest */
static int dk_rr_singular(int k, const double F[4][4])
{
    double values[490], A6[6][9], B6[6][9], C6[6][9], pencil[3][12][12];
    int i, c;
    for (i = 0; i < 490; i++) {
        values[i] = 0.0;
    }
    dk_rr_fill(k, F[0][2], F[1][2], F[2][2], F[0][3], F[1][3], F[2][3], values);
    if (!dk_rr_pencil6(values, A6, B6, C6)) {
        return 0;
    }
    for (c = 0; c < 3; c++) {
        dk_rr_pencil((const double(*)[9])A6, (const double(*)[9])B6, (const double(*)[9])C6,
                     DK_RR_MOEBIUS[c], pencil);
        if (!(dk_pivot_ratio((const double(*)[12])pencil[0], 1) * DK_RR_SINGULAR >= 1.0)) {
            return 0;
        }
    }
    return 1;
}

/* The general method's solutions of one pose into out (the first DK_RR_ROWS found where a
   self-motion gives more; then, on a nominal table, up to DK_RR_SEEDS seeds of its near
   misses, for the caller to refine and certify): their count (0: the pose out of reach, as
   the Python solver's _general finds it). flanges: per split, the 12 top entries of the
   target in the split's frame. */
static int dk_general(const double flanges[DK_RR_SPLIT_COUNT][12], double out[DK_RR_OUT][6])
{
    double targets[DK_RR_SPLIT_COUNT][4][4], moved[4][4], seeds[DK_RR_SEEDS][6];
    dk_rr_leads leads;
    int count = 0, doubt = DK_RR_RESCUE, perturbed = 0, grew = 0, n_seeds = 0, tried = 0, k, r;
    int c, m, i, regular = 1;
    /* (an out-of-reach answer from the first split alone where its table is the arm's own,
       exact: the Python solver's _general) */
    const int alone = !dk_rr_perturbed(0) && !(DK_SEED_TOL > 0.0);
    leads.n = leads.n_near = leads.singular = leads.clear = 0;
    for (k = 0; k < DK_RR_SPLIT_COUNT; k++) {
        for (r = 0; r < 4; r++) {
            for (c = 0; c < 4; c++) {
                targets[k][r][c] = r < 3 ? flanges[k][4 * r + c] : (c == 3 ? 1.0 : 0.0);
            }
            if (r < 3) {
                targets[k][r][3] /= DK_RR_LENGTH;
            }
        }
    }
    for (k = 0; k < DK_RR_SPLIT_COUNT; k++) {
        const int before = count;
        count = dk_rr_split(k, (const double(*)[4])targets[k], (const double(*)[4])targets[k],
                            out, count, &doubt, DK_RR_IMAG_TOL, seeds, &n_seeds, &leads);
        tried++;
        perturbed |= dk_rr_perturbed(k); /* (a perturbed table walked: the partners below) */
        grew |= k > 0 && count > before; /* (the fallback found what the first split missed) */
        if (count == DK_RR_ROWS) {
            return count;
        }
        if (!doubt && count % 2 == 0 && (count > 0 || !leads.clear || alone)) {
            break; /* (nothing found and nothing nearly real: the fallback split too) */
        }
    }
    if (count == 0 && (tried == DK_RR_SPLIT_COUNT || alone) && !doubt && leads.clear &&
        leads.n == 0 && leads.n_near == 0 && n_seeds == 0) {
        for (k = 0; k < tried && regular; k++) {
            regular = dk_rr_perturbed(k) || !dk_rr_singular(k, (const double(*)[4])targets[k]);
        }
        if (regular) { /* a pose out of reach: the Python solver's _general says why */
            return 0;
        }
    }
    for (r = 0; r < count && perturbed && !(doubt & DK_RR_RESCUE); r++) {
        doubt |= dk_rr_near_singular(out[r]) ? DK_RR_RESCUE : 0; /* (solutions meet there) */
    }
    if ((doubt & DK_RR_RESCUE) || grew || count == 0 || count % 2) {
        for (m = 0; m < DK_RR_MOTION_COUNT; m++) {
            for (k = 0; k < DK_RR_SPLIT_COUNT; k++) {
                int ignored;
                for (r = 0; r < 4; r++) {
                    for (c = 0; c < 4; c++) {
                        double total = 0.0;
                        for (i = 0; i < 4; i++) {
                            total += targets[k][r][i] * DK_RR_MOTIONS[m][i][c];
                        }
                        moved[r][c] = total;
                    }
                }
                count = dk_rr_split(k, (const double(*)[4])targets[k], (const double(*)[4])moved,
                                    out, count, &ignored, DK_RR_IMAG_TOL, seeds, &n_seeds, &leads);
                perturbed |= dk_rr_perturbed(k);
                if (count == DK_RR_ROWS) {
                    return count;
                }
            }
        }
    }
    if (count > 0 && count < DK_RR_ROWS && perturbed) {
        /* a perturbed table walks two solutions that share the eigen-joint value (the PUMA's
           wrist flip) onto one now and then, whether the count stays even or not: where such
           a table answered */
        count = dk_rr_partners((const double(*)[4])targets[0], out, count);
    }
    if (count % 2) {
        count = dk_rr_search((const double(*)[4])targets[0], (const double(*)[6])out, count, out,
                             count);
    }
    /* the last resort: a pose whose pencil is singular (a curve of solutions) scatters the
       eigenvalues off the real line; those within DK_RR_IMAG_LOOSE of it, polished */
    for (m = -1; m < DK_RR_MOTION_COUNT && count == 0; m++) {
        for (k = 0; k < DK_RR_SPLIT_COUNT; k++) {
            int ignored;
            for (r = 0; r < 4; r++) {
                for (c = 0; c < 4; c++) {
                    double total = 0.0;
                    for (i = 0; i < 4; i++) { /* m = -1: the pose itself */
                        const double w = m < 0 ? (i == c ? 1.0 : 0.0) : DK_RR_MOTIONS[m][i][c];
                        total += targets[k][r][i] * w;
                    }
                    moved[r][c] = total;
                }
            }
            count = dk_rr_split(k, (const double(*)[4])targets[k], (const double(*)[4])moved,
                                out, count, &ignored, DK_RR_IMAG_LOOSE, seeds, &n_seeds, &leads);
            if (count == DK_RR_ROWS) {
                return count;
            }
        }
    }
    for (k = 0; k < DK_RR_SPLIT_COUNT && count == 0 && leads.n_near == 0 && !leads.singular &&
                leads.n == 0;
         k++) { /* (a pencil singular to roundings at the pose, which its eigenvalues do not
                   show) */
        leads.singular = !dk_rr_perturbed(k) && dk_rr_singular(k, (const double(*)[4])targets[k]);
    }
    if (count == 0 && leads.n_near == 0 && (leads.singular || leads.n > 0)) {
        /* a curve of solutions that none of the above reached: a search from the leads */
        count = dk_rr_search((const double(*)[4])targets[0], (const double(*)[6])leads.rows,
                             leads.n, out, count);
    }
    if (count == 0 && n_seeds == 0) { /* (a singular pose, where Newton converges slowly: what
                                         came within DK_RR_NEAR, for the caller to certify) */
        for (r = 0; r < leads.n_near; r++) {
            for (i = 0; i < 6; i++) {
                out[r][i] = leads.near[r][i];
            }
        }
        count = leads.n_near;
    }
    for (r = 0; r < n_seeds && count < DK_RR_OUT; r++) { /* (a budget of their own) */
        /* a nominal table's near misses: seeds the caller refines onto the exact arm and
           certifies there (a pair of the exact arm near a fold, complex on the nominal table) */
        double split[6];
        int j;
        for (j = 0; j < 6; j++) { /* (the arm's values as split 0's, for dk_rr_add) */
            split[j] = DK_RR_REVERSED[0] ? -seeds[r][5 - j] : seeds[r][j];
        }
        if (DK_RR_TRUE[0][6][0] != 0.0) {
            split[2] /= DK_RR_LENGTH;
        }
        count = dk_rr_add(0, split, out, count);
    }
    return count;
}
