/* The process entry of the static ARMv4T ELF (no C library): the Linux ELF loader leaves argc
 * at [sp], then argv[0..argc-1], NULL, envp..., NULL (ARM ELF ABI, process initialisation).
 * _start clears .bss (the kernel maps it zeroed; cleared again so the image also starts from a
 * boot loader that does not), aligns sp to 8 bytes as the AAPCS requires at a public call,
 * calls main(argc, argv) and passes its result to sys_exit. ARM mode, ARMv4T instructions. */
        .arm
        .syntax unified
        .text
        .global _start
        .type   _start, %function
_start:
        mov     fp, #0                  @ outermost frame: stack walks stop here
        mov     lr, #0
        ldr     r4, [sp]                @ argc
        add     r5, sp, #4              @ argv
        bic     sp, sp, #7
        ldr     r0, =__bss_start__
        ldr     r1, =__bss_end__
        mov     r2, #0
1:      cmp     r0, r1
        strbcc  r2, [r0], #1
        bcc     1b
        mov     r0, r4
        mov     r1, r5
        bl      main
        bl      sys_exit
        .size   _start, . - _start
        .ltorg
