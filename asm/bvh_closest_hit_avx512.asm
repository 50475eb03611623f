; Closest hit of one ray in the tree (src/accel/bvh.h), AVX-512 (F and VL,
; on 8-lane ymm registers: a node has eight children). What it adds to the
; AVX2 traversal is in the bookkeeping, not the arithmetic: comparisons into
; mask registers, the ray's constants kept in ymm16-25 instead of the frame,
; a node's children entered in one step: the nearest is entered at once,
; without a round trip through the stack, and the others are compressed
; (vcompressps, vpcompressd) onto three stacks, of entry distances, children
; and leaf counts, with one store each instead of a loop over the lanes; and
; the huge spheres left out of the tree tested last, so that the first node test
; does not wait on their square roots (on the recorded rays of a 10^5-sphere
; cloud, 1.1x as fast; bench/query).
;
; Returns exactly what ptr_bvh_closest_hit_c returns: the box test and the
; sphere arithmetic are the same operations in the same order as there (no
; FMA; maxps and minps where C writes its max and min), so the same boxes are
; visited or safely skipped and every t is the brute-force kernel's bit for
; bit. The answer, the smallest (t, id) with tmin < t < tmax, does not depend
; on the order of the visits.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"
%include "bvh.inc"

section .rodata
align 32
lane_index: dd 0, 1, 2, 3, 4, 5, 6, 7
sign_mask:  dd 0x80000000
one:        dd 0x3f800000
flt_max:    dd 0x7f7fffff
slack:      dd PTR_BVH_SLACK
infinity:   dd 0x7f800000

section .text

; The frame, at rbp: the three stacks (entry distance, child, leaf count),
; each with room for a full vector stored past its top; the rsp to return
; with.
STACK_SIZE  equ 4 * (PTR_BVH_MAX_DEPTH * 7 + 8)
STACK_ENTRY equ 0
STACK_CHILD equ STACK_SIZE
STACK_COUNT equ 2 * STACK_SIZE
FRAME       equ 3 * STACK_SIZE + 8

; Tests spheres eax .. eax + ecx - 1 (1 <= ecx <= 8): for every lane
; whose t beats the best, (t, position) lexicographically; the smallest such
; t, at its lowest lane, becomes the best.
; In: r8-r11 cx, cy, cz, radius; r15d the best sphere; ymm0-2
; direction; ymm3 tmin; ymm4 best t in every lane; ymm6 lane indices; ymm7
; sign mask; ymm16-18 the origin; ymm22 the slack, ymm23 +inf, ymm25 zero.
; Out: ymm4, r15d and ymm24 (best * slack) updated.
; Clobbers rdx, ymm8-15, k1-k4.
test_eight:
    vsubps      ymm8, ymm16, [r8 + rax*4]       ; fx = ox - cx
    vsubps      ymm9, ymm17, [r9 + rax*4]       ; fy
    vsubps      ymm10, ymm18, [r10 + rax*4]     ; fz
    DISCRIMINANT y, vmovups
    vcmpps      k1, ymm12, ymm25, CMP_GE_OQ     ; disc >= 0
    vpbroadcastd ymm14, ecx
    vpcmpgtd    k1{k1}, ymm14, ymm6             ; ... and lane < count
    kortestw    k1, k1
    jz          .done                           ; no lane can hit: skip sqrt, div
    ROOT_AVX2
    vcmpps      k2{k1}, ymm9, ymm3, CMP_GT_OQ   ; tmin < t
    vcmpps      k3{k2}, ymm9, ymm4, CMP_EQ_OQ   ; t == best: the positions decide
    vcmpps      k2{k2}, ymm9, ymm4, CMP_LT_OQ   ; t < best
    kortestw    k3, k3
    jnz         .tie
.settled:
    kortestw    k2, k2
    jz          .done
    vblendmps   ymm11{k2}, ymm23, ymm9          ; the winners' t, else +inf
    vextractf128 xmm8, ymm11, 1
    vminps      xmm8, xmm8, xmm11
    HORIZONTAL_MIN_XMM8
    vbroadcastss ymm4, xmm8                     ; best
    vcmpps      k3{k2}, ymm11, ymm4, CMP_EQ_OQ
    kmovw       edx, k3
    bsf         edx, edx                        ; the lowest winning lane
    add         edx, eax
    mov         r15d, edx
    vmulps      ymm24, ymm4, ymm22
.done:
    ret
    ; A t equal to the best one's (rare): the first in the arrays wins. The
    ; best was found by an earlier call, so these spheres all come before it
    ; or all after: the first one's position decides for every lane. Signed:
    ; positions are below 2^31 and PTR_NO_HIT, -1, below them all, so before
    ; any hit (when the best t is tmax) no tie wins.
.tie:
    cmp         eax, r15d
    jge         .settled
    korw        k2, k2, k3
    jmp         .settled

TEST_LEAF_BY_EIGHT

; int ptr_bvh_closest_hit_avx512(const PtrRay *ray, const PtrBvh *bvh,
;                                const PtrSpheres *spheres, PtrHit *hit);
;
; rdi ray, rsi bvh (then the node being tested), rdx spheres (then scratch),
; rcx hit (pushed; then scratch)
; r8-r11 cx, cy, cz, radius   r13 nodes   r14 entries on the stacks
; r15d best sphere (PTR_NO_HIT)   rbx huge spheres left out of the tree   rbp the frame
; ymm0-2 dx, dy, dz   ymm3 tmin   ymm4 best t   ymm6 lane indices
; ymm7 sign mask   ymm8-15 scratch   ymm16-18 ox, oy, oz
; ymm19-21 1 / d clamped   ymm22 slack   ymm23 +inf   ymm24 best * slack
; ymm25 zero   k5-k7 the lanes of each axis whose 1 / d is negative (all or
; none)
FUNCTION ptr_bvh_closest_hit_avx512
    TREE_ENTRY  FRAME, 64
    vbroadcastss ymm0, [rdi + RAY_DIR_X]
    vbroadcastss ymm1, [rdi + RAY_DIR_Y]
    vbroadcastss ymm2, [rdi + RAY_DIR_Z]
    vbroadcastss ymm3, [rdi + RAY_TMIN]
    vbroadcastss ymm4, [rdi + RAY_TMAX]
    vmovdqu     ymm6, [lane_index]
    vbroadcastss ymm7, [sign_mask]
    vbroadcastss ymm16, [rdi + RAY_ORG_X]
    vbroadcastss ymm17, [rdi + RAY_ORG_Y]
    vbroadcastss ymm18, [rdi + RAY_ORG_Z]
    vbroadcastss ymm22, [slack]
    vbroadcastss ymm23, [infinity]
    vmulps      ymm24, ymm4, ymm22
    vpxord      ymm25, ymm25, ymm25
    mov         r15d, -1                        ; PTR_NO_HIT

.tree:
    test        r13, r13
    jz          .huge
    RECIPROCALS_AVX512
    xor         r14d, r14d
    xor         eax, eax                        ; the root

.node:
    shl         rax, 8                          ; 256-byte nodes
    lea         rsi, [r13 + rax]
    BOX_ENTRY_EXIT_AVX512 vmovaps, , 10, 13     ; the eight children's
    vcmpps      k1, ymm10, ymm13, CMP_LE_OQ
    kmovw       eax, k1
    test        eax, eax
    jz          .pop
    lea         ecx, [rax - 1]
    test        eax, ecx
    jz          .one                            ; one child entered
    ; Several: the nearest (its lowest lane on a tie) is entered next, the
    ; others go onto the stacks in lane order.
    vblendmps   ymm11{k1}, ymm23, ymm10         ; entries, +inf where not entered
    vextractf128 xmm8, ymm11, 1
    vminps      xmm8, xmm8, xmm11
    HORIZONTAL_MIN_XMM8
    vbroadcastss ymm8, xmm8
    vcmpps      k2{k1}, ymm11, ymm8, CMP_EQ_OQ
    kmovw       edx, k2
    bsf         edx, edx
    btr         eax, edx
    kmovw       k3, eax
    vcompressps ymm8{k3}{z}, ymm10
    vmovups     [rbp + STACK_ENTRY + r14*4], ymm8
    vmovdqa     ymm9, [rsi + NODE_CHILD]
    vpcompressd ymm9{k3}{z}, ymm9
    vmovdqu     [rbp + STACK_CHILD + r14*4], ymm9
    vmovdqa     ymm9, [rsi + NODE_LEAF_COUNT]
    vpcompressd ymm9{k3}{z}, ymm9
    vmovdqu     [rbp + STACK_COUNT + r14*4], ymm9
    popcnt      eax, eax
    add         r14, rax
    jmp         .enter
.one:
    bsf         edx, eax
.enter:
    mov         eax, [rsi + NODE_CHILD + rdx*4]
    mov         ecx, [rsi + NODE_LEAF_COUNT + rdx*4]
    test        ecx, ecx
    jz          .node
    call        test_leaf

.pop:
    test        r14, r14
    jz          .huge
    dec         r14
    vmovss      xmm8, [rbp + STACK_ENTRY + r14*4]
    vucomiss    xmm8, xmm24
    ja          .pop                            ; entered beyond the best hit
    mov         eax, [rbp + STACK_CHILD + r14*4]
    mov         ecx, [rbp + STACK_COUNT + r14*4]
    test        ecx, ecx
    jz          .node
    call        test_leaf
    jmp         .pop

    ; The huge spheres left out of the tree, eight at a time, once the tree has
    ; found its best: the tree's first node test need not wait for them.
.huge:
    TEST_KEPT_OUT rbx
.finish:
    TREE_LEAVE_FRAME FRAME
    TREE_RETURN_HIT

section .note.GNU-stack noalloc noexec nowrite progbits
